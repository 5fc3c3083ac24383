// SPDX-License-Identifier: Apache-2.0
// The growable structs of ccomm.h (see "Growable structs" there): a call fills the
// library's whole struct, then hands the caller the bytes its sizeof covers.
#pragma once

#include <stddef.h>
#include <string.h>

#include "ccomm/ccomm.h"

namespace ccomm::client {

// The size each struct had when its *_sized call appeared (ccomm 0.2.0): the smallest a
// caller may pass. Fixed forever: the end of the member that was last then, rounded to the
// struct's alignment, so it is right on every ABI (a 32-bit board's pointers are 4 bytes)
// and stays put when members are appended.
constexpr size_t EndOfFirstLayout(size_t member_end, size_t align) { return (member_end + align - 1) / align * align; }
#define CCOMM_FIRST_LAYOUT_ENDS_AT(T, last)                                                          \
  template <>                                                                                        \
  struct FirstSize<T> {                                                                              \
    static constexpr size_t value = EndOfFirstLayout(offsetof(T, last) + sizeof(T::last), alignof(T)); \
  }
template <typename T> struct FirstSize;
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_signal_desc, consumed_here);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_signal_stats, values_incomplete);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_peer_stats, last_rx_age_ns);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_view_node, summaries);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_view_signal, age_ns);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_view_counters, summary_ms);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_peer_clock, frames_delayed);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_clock_state, path_delay_ns);
CCOMM_FIRST_LAYOUT_ENDS_AT(ccomm_production_age, error_ns);
#undef CCOMM_FIRST_LAYOUT_ENDS_AT

// Copies `full` into the caller's `size` bytes at `out`: the first min(size, sizeof)
// bytes, zeros beyond (a caller built against a newer header). CCOMM_E_INVAL for a
// size below the struct's first size; `rc` (the fill's result) when that failed.
template <typename T>
int CopySized(int rc, const T& full, void* out, size_t size) {
  static_assert(FirstSize<T>::value <= sizeof(T), "a growable struct only grows");
  if (!out || size < FirstSize<T>::value) return CCOMM_E_INVAL;
  if (rc != 0) return rc;
  const size_t known = size < sizeof(T) ? size : sizeof(T);
  memcpy(out, &full, known);
  if (size > known) memset(static_cast<char*>(out) + known, 0, size - known);
  return 0;
}

}  // namespace ccomm::client

// SPDX-License-Identifier: Apache-2.0
// The growable structs of ccomm.h (see "Growable structs" there): a call fills the
// library's whole struct, then hands the caller the bytes its sizeof covers.
#pragma once

#include <stddef.h>
#include <string.h>

#include "ccomm/ccomm.h"

namespace ccomm::client {

// The size each struct had when its *_sized call appeared (ccomm 0.2.0): the smallest a
// caller may pass. Fixed forever; the structs only grow beyond it.
template <typename T> struct FirstSize;
template <> struct FirstSize<ccomm_signal_desc> { static constexpr size_t value = 48; };
template <> struct FirstSize<ccomm_signal_stats> { static constexpr size_t value = 104; };
template <> struct FirstSize<ccomm_peer_stats> { static constexpr size_t value = 72; };
template <> struct FirstSize<ccomm_view_node> { static constexpr size_t value = 112; };
template <> struct FirstSize<ccomm_view_signal> { static constexpr size_t value = 40; };
template <> struct FirstSize<ccomm_view_counters> { static constexpr size_t value = 48; };
template <> struct FirstSize<ccomm_peer_clock> { static constexpr size_t value = 40; };
template <> struct FirstSize<ccomm_clock_state> { static constexpr size_t value = 24; };

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

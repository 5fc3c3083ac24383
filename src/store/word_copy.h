// SPDX-License-Identifier: Apache-2.0
// Copies values in and out of shared memory one 64-bit word at a time with relaxed
// atomics. The seqlock protocols (state_slot.h, event_ring.h) decide whether a copy
// is valid; copying through atomics keeps the racing accesses defined behaviour (and
// visible as such to TSan). Shared-memory side is 8-byte aligned, padded to 8 bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace ccomm {
namespace store {

inline void StoreWords(uint8_t* shm, const void* src, size_t len) {
  const uint8_t* s = static_cast<const uint8_t*>(src);
  for (size_t i = 0; i < len; i += 8) {
    uint64_t w = 0;
    std::memcpy(&w, s + i, len - i < 8 ? len - i : 8);  // the tail word is zero-padded
    __atomic_store_n(reinterpret_cast<uint64_t*>(shm + i), w, __ATOMIC_RELAXED);
  }
}

inline void LoadWords(void* dst, const uint8_t* shm, size_t len) {
  uint8_t* d = static_cast<uint8_t*>(dst);
  for (size_t i = 0; i < len; i += 8) {
    uint64_t w = __atomic_load_n(reinterpret_cast<const uint64_t*>(shm + i), __ATOMIC_RELAXED);
    std::memcpy(d + i, &w, len - i < 8 ? len - i : 8);
  }
}

}  // namespace store
}  // namespace ccomm

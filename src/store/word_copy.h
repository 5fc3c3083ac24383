// SPDX-License-Identifier: Apache-2.0
// Copies values in and out of shared memory one 64-bit word at a time with relaxed
// atomics. The seqlock protocols (state_slot.h, event_ring.h) decide whether a copy
// is valid; copying through atomics keeps the racing accesses defined behaviour (and
// visible as such to TSan). Shared-memory side is 8-byte aligned, padded to 8 bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <atomic>
#include <cstring>

namespace ccomm {
namespace store {

// Seqlock ordering. Normally: relaxed data accesses between a release fence (writer)
// and an acquire fence (reader). ThreadSanitizer does not model stand-alone fences
// (GCC refuses to compile them), so under TSan the fences go away and every data
// access carries the ordering itself (release stores / acquire loads), which is the
// same protocol without fences and what TSan then checks.
#if defined(__SANITIZE_THREAD__)
#define CCOMM_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define CCOMM_TSAN 1
#endif
#endif
#ifdef CCOMM_TSAN
constexpr int kDataStoreOrder = __ATOMIC_RELEASE;
constexpr int kDataLoadOrder = __ATOMIC_ACQUIRE;
constexpr std::memory_order kMetaStore = std::memory_order_release;
constexpr std::memory_order kMetaLoad = std::memory_order_acquire;
inline void SeqlockWriterFence() {}
inline void SeqlockReaderFence() {}
#else
constexpr int kDataStoreOrder = __ATOMIC_RELAXED;
constexpr int kDataLoadOrder = __ATOMIC_RELAXED;
constexpr std::memory_order kMetaStore = std::memory_order_relaxed;
constexpr std::memory_order kMetaLoad = std::memory_order_relaxed;
/// After claiming (seq odd), before the data stores.
inline void SeqlockWriterFence() { std::atomic_thread_fence(std::memory_order_release); }
/// After the data loads, before re-reading seq.
inline void SeqlockReaderFence() { std::atomic_thread_fence(std::memory_order_acquire); }
#endif

// Whole words with a constant-size memcpy (a plain load/store), the tail word apart:
// a variable-size memcpy per word would be a library call per word.
inline void StoreWords(uint8_t* shm, const void* src, size_t len) {
  const uint8_t* s = static_cast<const uint8_t*>(src);
  if (len == 8) {  // the common value (one double or int64): no loop
    uint64_t w;
    std::memcpy(&w, s, 8);
    __atomic_store_n(reinterpret_cast<uint64_t*>(shm), w, kDataStoreOrder);
    return;
  }
  const size_t full = len & ~size_t{7};
  for (size_t i = 0; i < full; i += 8) {
    uint64_t w;
    std::memcpy(&w, s + i, 8);
    __atomic_store_n(reinterpret_cast<uint64_t*>(shm + i), w, kDataStoreOrder);
  }
  if (full != len) {
    uint64_t w = 0;  // the tail word is zero-padded
    std::memcpy(&w, s + full, len - full);
    __atomic_store_n(reinterpret_cast<uint64_t*>(shm + full), w, kDataStoreOrder);
  }
}

inline void LoadWords(void* dst, const uint8_t* shm, size_t len) {
  uint8_t* d = static_cast<uint8_t*>(dst);
  if (len == 8) {
    const uint64_t w = __atomic_load_n(reinterpret_cast<const uint64_t*>(shm), kDataLoadOrder);
    std::memcpy(d, &w, 8);
    return;
  }
  const size_t full = len & ~size_t{7};
  for (size_t i = 0; i < full; i += 8) {
    uint64_t w = __atomic_load_n(reinterpret_cast<const uint64_t*>(shm + i), kDataLoadOrder);
    std::memcpy(d + i, &w, 8);
  }
  if (full != len) {
    uint64_t w = __atomic_load_n(reinterpret_cast<const uint64_t*>(shm + full), kDataLoadOrder);
    std::memcpy(d + full, &w, len - full);
  }
}

}  // namespace store
}  // namespace ccomm

// SPDX-License-Identifier: Apache-2.0
// Heap-allocation counter, LD_PRELOADed into ccommd by the zero-allocation test.
// ccommd calls ccomm_steady_state_begin() once start-up is done and
// ccomm_steady_state_end() when asked to stop; every malloc/calloc/realloc/
// posix_memalign/aligned_alloc in between, from any thread, is counted. At exit the
// count goes to $CCOMM_ALLOC_REPORT ("steady_state_allocations N", then "total_allocations M" incl. start-up).
// CCOMM_ALLOC_BACKTRACE=1: each steady-state allocation also prints its call stack to stderr
// (to find which code allocated; addr2line -e ccommd turns the addresses into lines).
#include <execinfo.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <atomic>

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> g_counting{false};
std::atomic<unsigned long> g_count{0}, g_total{0};
thread_local bool t_in_backtrace = false;
inline void Count() {
  g_total.fetch_add(1, std::memory_order_relaxed);  // proves the interposer is live
  if (!g_counting.load(std::memory_order_relaxed)) return;
  g_count.fetch_add(1, std::memory_order_relaxed);
  static const bool trace = getenv("CCOMM_ALLOC_BACKTRACE") != nullptr;
  if (trace && !t_in_backtrace) {
    t_in_backtrace = true;  // backtrace() may allocate once (loading libgcc)
    void* frames[32];
    const int n = backtrace(frames, 32);
    fputs("steady-state allocation:\n", stderr);
    backtrace_symbols_fd(frames, n, 2);
    t_in_backtrace = false;
  }
}
}  // namespace

extern "C" {

void* malloc(size_t n) {
  Count();
  return __libc_malloc(n);
}
void* calloc(size_t a, size_t b) {
  Count();
  return __libc_calloc(a, b);
}
void* realloc(void* p, size_t n) {
  Count();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
int posix_memalign(void** out, size_t align, size_t n) {
  Count();
  *out = __libc_memalign(align, n);
  return *out ? 0 : 12;
}
void* aligned_alloc(size_t align, size_t n) {
  Count();
  return __libc_memalign(align, n);
}

void ccomm_steady_state_begin() { g_counting.store(true); }
void ccomm_steady_state_end() {
  g_counting.store(false);
  const char* path = getenv("CCOMM_ALLOC_REPORT");
  if (!path) return;
  FILE* f = fopen(path, "w");
  if (!f) return;
  fprintf(f, "steady_state_allocations %lu\ntotal_allocations %lu\n", g_count.load(), g_total.load());
  fclose(f);
}

}  // extern "C"

// SPDX-License-Identifier: Apache-2.0
// Client reads and writes allocate nothing: this binary interposes malloc and counts
// calls made while the calling thread is inside the measured region.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>

#include "ccomm/ccomm.hpp"
#include "common/platform.h"
#include "daemon/engine/segment_builder.h"
#include "store/segment.h"
#include "testing/test_config.h"

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void __libc_free(void*);
}

namespace {
thread_local bool t_counting = false;
unsigned long g_allocs = 0;
}  // namespace

extern "C" {
void* malloc(size_t n) {
  if (t_counting) g_allocs++;
  return __libc_malloc(n);
}
void* calloc(size_t a, size_t b) {
  if (t_counting) g_allocs++;
  return __libc_calloc(a, b);
}
void* realloc(void* p, size_t n) {
  if (t_counting) g_allocs++;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}

namespace ccomm {
namespace {

TEST(ClientAlloc, ReadWriteFlushWaitAllocateNothing) {
  setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("alloc").c_str(), 1);
  auto s1 = testing::MakeSignal("x", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
  auto s2 = testing::MakeSignal("arr", ValueType::kFloat, 36, SignalKind::kState, 0, {0});
  auto s3 = testing::MakeSignal("ev", ValueType::kInt32, 1, SignalKind::kEvent, 0, {1});
  s3.queue_depth = 64;
  auto s4 = testing::MakeSignal("in", ValueType::kDouble, 1, SignalKind::kState, 1, {0});
  s4.stale_after_ms = 5;
  s4.has_safe_value = true;
  s4.safe_value.assign(8, 0);
  SystemConfig cfg = testing::TwoNodeConfig({s1, s2, s3, s4});
  store::Segment seg;
  std::string err;
  bool adopted;
  ASSERT_EQ(CreateOrAdoptSegment(&seg, cfg, 0, store::SegmentName("a"), -1, &adopted, &err), 0);
  seg.header()->tx_sleeping.store(1);  // make writes take the FUTEX_WAKE path too

  Client plain("a"), batch("a", CCOMM_OPEN_BATCH);
  auto x = plain.signal<double>("x");
  auto arr = plain.signal<std::array<float, 36>>("arr");
  auto ev = plain.signal<int32_t>("ev");
  auto in = plain.signal<double>("in");
  auto bx = batch.signal<double>("x");
  ASSERT_TRUE(x.valid() && arr.valid() && ev.valid() && in.valid() && bx.valid());
  std::array<float, 36> a{};

  g_allocs = 0;
  t_counting = true;
  for (int i = 0; i < 10000; ++i) {
    x.write(i);
    a[0] = static_cast<float>(i);
    arr.write(a);
    (void)arr.read();
    ev.write(i);
    (void)in.read();
    bx.write(i);
    ccomm_flush(batch.raw());
    double d;
    ccomm_info info;
    ccomm_read_double(plain.raw(), in.id(), &d, &info);
  }
  ccomm_wait(plain.raw(), 0);
  t_counting = false;
  EXPECT_EQ(g_allocs, 0u);
  // The counter itself works: an allocation in the measured region is seen.
  t_counting = true;
  void* volatile p = malloc(64);
  t_counting = false;
  free(p);
  EXPECT_EQ(g_allocs, 1u);
  platform::ShmUnlink(store::SegmentName("a").c_str());
}

}  // namespace
}  // namespace ccomm

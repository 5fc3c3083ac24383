// SPDX-License-Identifier: Apache-2.0
// Unit tests of the platform layer's Windows unit (platform/windows/platform.cpp): named
// file mappings with their exact size, futex words through named events, processes.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>

#include "common/platform.h"

namespace {

namespace pf = ccomm::platform;

std::string UniqueName(const char* tag) {
  return "/ccomm-test-" + std::string(tag) + "-" + std::to_string(pf::ProcessId());
}

TEST(WindowsShm, CreateSizeMapReopenAndRefuseASecondCreate) {
  const std::string name = UniqueName("shm");
  int fd = pf::ShmOpen(name.c_str(), true, 0600);
  ASSERT_GE(fd, 0);
  // A mapping is made when it is sized (Windows needs the size): of two creators racing
  // before that, the second to size it is refused.
  int rival = pf::ShmOpen(name.c_str(), true, 0600);
  ASSERT_GE(rival, 0);
  ASSERT_EQ(pf::Truncate(fd, 10000), 0);  // not a whole number of pages
  EXPECT_EQ(pf::Truncate(rival, 10000), -EEXIST);
  pf::CloseFd(rival);
  auto* p = static_cast<unsigned char*>(pf::MapShared(fd, 10000));
  ASSERT_NE(p, nullptr);
  pf::CloseFd(fd);  // the mapping keeps the name alive
  EXPECT_EQ(p[0], 0);
  EXPECT_EQ(p[9999], 0);
  p[0] = 42;
  p[9999] = 43;
  EXPECT_EQ(pf::ShmOpen(name.c_str(), true, 0600), -EEXIST);

  int ro = pf::ShmOpenReadOnly(name.c_str());
  ASSERT_GE(ro, 0);
  size_t size = 0;
  ASSERT_EQ(pf::FileSize(ro, &size), 0);
  EXPECT_EQ(size, 10000u) << "the exact size, not rounded to pages";
  auto* q = static_cast<const unsigned char*>(pf::MapSharedReadOnly(ro, size));
  ASSERT_NE(q, nullptr);
  pf::CloseFd(ro);
  EXPECT_EQ(q[0], 42);
  EXPECT_EQ(q[9999], 43);
  pf::Unmap(const_cast<unsigned char*>(q), size);
  pf::Unmap(p, 10000);
  EXPECT_EQ(pf::ShmOpen(name.c_str(), false, 0), -ENOENT) << "gone with its last mapping";
}

TEST(WindowsShm, OpeningAMissingObjectSaysENOENT) {
  EXPECT_EQ(pf::ShmOpen(UniqueName("missing").c_str(), false, 0), -ENOENT);
  EXPECT_EQ(pf::ShmOpenReadOnly(UniqueName("missing").c_str()), -ENOENT);
}

// Two mappings of one object stand for two processes: a wake through one mapping's word
// must reach a waiter on the other's (the same named event).
TEST(WindowsFutex, AWakeThroughOneMappingReachesAWaiterOnAnother) {
  const std::string name = UniqueName("futex");
  int fd = pf::ShmOpen(name.c_str(), true, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(pf::Truncate(fd, 4096), 0);
  void* a = pf::MapShared(fd, 4096);
  void* b = pf::MapShared(fd, 4096);
  pf::CloseFd(fd);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  ASSERT_NE(a, b);
  auto* wa = reinterpret_cast<std::atomic<uint32_t>*>(static_cast<char*>(a) + 64);
  auto* wb = reinterpret_cast<std::atomic<uint32_t>*>(static_cast<char*>(b) + 64);
  pf::FutexPrepare(wa);
  pf::FutexPrepare(wb);

  EXPECT_FALSE(pf::FutexWait(wb, 0, 20000000)) << "nothing changed: times out";
  // A waiter that missed the wake would return only at its 20 s timeout, seeing the
  // word changed by then: woken means back well before that.
  constexpr uint64_t kTimeoutNs = 20000000000ull, kWokenWithinNs = 5000000000ull;
  std::atomic<int> woken{0};
  std::atomic<uint64_t> wake_ns{0};
  std::thread waiters[3];
  for (auto& t : waiters)
    t = std::thread([&] {
      if (pf::FutexWait(wb, 0, static_cast<int64_t>(kTimeoutNs)) && pf::MonotonicNs() - wake_ns.load() < kWokenWithinNs)
        woken.fetch_add(1);
    });
  pf::SleepNs(20000000);
  wake_ns.store(pf::MonotonicNs());
  wa->store(1);
  pf::FutexWake(wa, 1 << 30);
  for (auto& t : waiters) t.join();
  EXPECT_EQ(woken.load(), 3) << "every waiter of a wake-all wakes";
  EXPECT_TRUE(pf::FutexWait(wb, 0, 0)) << "the word differs: returns at once";
  pf::Unmap(a, 4096);
  pf::Unmap(b, 4096);
}

TEST(WindowsFutex, AProcessLocalWordWorksToo) {
  std::atomic<uint32_t> word{7};
  std::thread t([&] {
    pf::SleepNs(10000000);
    word.store(8);
    pf::FutexWake(&word, 1);
  });
  EXPECT_TRUE(pf::FutexWait(&word, 7, 10000000000ll));
  t.join();
}

TEST(WindowsClock, MonotonicAndSleepsAtLeastAsAsked) {
  const uint64_t t0 = pf::MonotonicNs();
  pf::SleepNs(2000000);
  const uint64_t t1 = pf::MonotonicNs();
  EXPECT_GE(t1 - t0, 2000000u);
  EXPECT_LT(t1 - t0, 2000000000u);
}

TEST(WindowsProcess, OwnPidAliveZeroNot) {
  EXPECT_NE(pf::ProcessId(), 0u);
  EXPECT_TRUE(pf::ProcessAlive(pf::ProcessId()));
  EXPECT_FALSE(pf::ProcessAlive(0));
  char host[64];
  EXPECT_TRUE(pf::HostName(host, sizeof host));
}

}  // namespace

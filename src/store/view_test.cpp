// SPDX-License-Identifier: Apache-2.0
// The system view object (view.h): creation, read-only mapping and its checks, and the
// per-node seqlock under a concurrent writer (run under TSan in the sanitizer builds).
#include "store/view.h"

#include <errno.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "common/platform.h"

namespace ccomm {
namespace store {
namespace {

std::string TestName(const char* tag) { return "/ccomm-view-test-" + std::to_string(getpid()) + "-" + tag; }

TEST(View, CreateWriteReadBack) {
  const std::string name = TestName("basic");
  View w;
  std::string err;
  ASSERT_EQ(w.Create(name, 3, 5, 1, 1000, -1, &err), 0) << err;
  w.BeginWrite(2);
  w.SetNodeWord(2, kVwLastRxNs, 123);
  w.SetNodeWord(2, kVwPeersAlive, 0x5);
  w.SetRow(2, 4, 2, 1, 1500, 7, 250, 999);
  w.EndWrite(2);

  View r;
  ASSERT_EQ(r.OpenReadOnly(name), 0);
  EXPECT_EQ(r.header()->node_count, 3u);
  EXPECT_EQ(r.header()->signal_count, 5u);
  EXPECT_EQ(r.header()->self, 1u);
  EXPECT_EQ(r.header()->summary_ms, 1000u);
  ViewNodeCopy n;
  ASSERT_TRUE(r.ReadNode(2, &n));
  EXPECT_EQ(n.w[kVwLastRxNs], 123u);
  EXPECT_EQ(n.w[kVwPeersAlive], 0x5u);
  ViewRowCopy row;
  ASSERT_TRUE(r.ReadRow(2, 4, &row));
  EXPECT_TRUE(row.present);
  EXPECT_EQ(row.role, 2);
  EXPECT_EQ(row.flags, 1);
  EXPECT_EQ(row.rate_mhz, 1500u);
  EXPECT_EQ(row.lost, 7u);
  EXPECT_EQ(row.age_ms, 250u);
  EXPECT_EQ(row.rx_ns, 999u);
  ASSERT_TRUE(r.ReadRow(2, 3, &row));
  EXPECT_FALSE(row.present);
  EXPECT_FALSE(r.ReadNode(3, &n)) << "node index out of range";
  EXPECT_FALSE(r.ReadRow(0, 5, &row)) << "signal index out of range";
  // The mapping is read-only and cannot be made writable (the object was opened
  // O_RDONLY): a client cannot corrupt what other clients read.
  EXPECT_EQ(mprotect(const_cast<ViewHeader*>(r.header()), 4096, PROT_READ | PROT_WRITE), -1);
  EXPECT_EQ(errno, EACCES);
  ASSERT_EQ(platform::ShmUnlink(name.c_str()), 0);
}

TEST(View, OpenRefusesWhatIsNoView) {
  View r;
  EXPECT_EQ(r.OpenReadOnly(TestName("missing")), -ENOENT);
  const std::string name = TestName("junk");
  int fd = platform::ShmOpen(name.c_str(), /*create_exclusive=*/true, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(ftruncate(fd, 4096), 0);  // zeros: not initialised, wrong magic
  close(fd);
  EXPECT_EQ(r.OpenReadOnly(name), -EPROTO);
  fd = platform::ShmOpen(name.c_str(), false, 0);
  ASSERT_EQ(ftruncate(fd, 8), 0);  // shorter than a header
  close(fd);
  EXPECT_EQ(r.OpenReadOnly(name), -EPROTO);
  platform::ShmUnlink(name.c_str());
  // A view whose recorded size disagrees with its dimensions.
  View w;
  std::string err;
  ASSERT_EQ(w.Create(name, 2, 2, 0, 0, -1, &err), 0) << err;
  w.mutable_header()->signal_count = 1000;
  EXPECT_EQ(r.OpenReadOnly(name), -EPROTO);
  platform::ShmUnlink(name.c_str());
}

// One writer rewrites node 1 and a row with the same number in every word; readers must
// never see a mixture (the seqlock), and must see progress.
TEST(View, SeqlockGivesConsistentCopies) {
  const std::string name = TestName("seqlock");
  View w;
  std::string err;
  ASSERT_EQ(w.Create(name, 2, 3, 0, 100, -1, &err), 0) << err;
  View r;
  ASSERT_EQ(r.OpenReadOnly(name), 0);
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    for (uint64_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
      w.BeginWrite(1);
      for (uint32_t k = 0; k < kVwNodeWords; ++k) w.SetNodeWord(1, static_cast<ViewNodeWord>(k), i);
      w.SetRow(1, 2, 1, 0, static_cast<uint32_t>(i), i, static_cast<uint32_t>(i), i);
      w.EndWrite(1);
    }
  });
  uint64_t last = 0, copies = 0, mixed = 0;
  // At least 300 ms, and on until some copies of the writer's values got through (a
  // loaded 2-CPU machine can starve the reader, or the writer thread before its first
  // write: CI once saw only the initial zeros in 300 ms; the test is about mixtures, not
  // speed), at most 10 s.
  const auto start = std::chrono::steady_clock::now();
  const auto until = start + std::chrono::milliseconds(300), give_up = start + std::chrono::seconds(10);
  for (auto now = start; now < until || ((copies < 100 || last == 0) && now < give_up);
       now = std::chrono::steady_clock::now()) {
    ViewNodeCopy n;
    if (r.ReadNode(1, &n)) {
      ++copies;
      for (uint32_t k = 1; k < kVwNodeWords; ++k) mixed += n.w[k] != n.w[0];
      EXPECT_GE(n.w[0], last);
      last = n.w[0];
    }
    ViewRowCopy row;
    if (r.ReadRow(1, 2, &row) && row.present) {
      mixed += row.lost != row.rx_ns || row.rate_mhz != static_cast<uint32_t>(row.lost) ||
               row.age_ms != static_cast<uint32_t>(row.lost);
    }
  }
  stop = true;
  writer.join();
  EXPECT_EQ(mixed, 0u);
  EXPECT_GT(copies, 0u);
  EXPECT_GT(last, 0u);
  platform::ShmUnlink(name.c_str());
}

}  // namespace
}  // namespace store
}  // namespace ccomm

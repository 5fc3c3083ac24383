// SPDX-License-Identifier: Apache-2.0
// Unit tests of the platform layer's calls that have observable behaviour of their own.
#include "common/platform.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>

namespace {

// A loopback UDP socket with the smallest receive buffer, flooded without reading:
// the kernel must drop, and SocketDrops must count exactly what did not fit.
TEST(SocketDrops, CountsWhatTheReceiveBufferCouldNotHold) {
  int rx = socket(AF_INET, SOCK_DGRAM, 0), tx = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(rx, 0);
  ASSERT_GE(tx, 0);
  int small = 1;  // the kernel rounds up to its minimum
  ASSERT_EQ(setsockopt(rx, SOL_SOCKET, SO_RCVBUF, &small, sizeof small), 0);
  sockaddr_in a = {};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(rx, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  socklen_t len = sizeof a;
  ASSERT_EQ(getsockname(rx, reinterpret_cast<sockaddr*>(&a), &len), 0);

  uint32_t drops = 99;
  ASSERT_EQ(ccomm::platform::SocketDrops(rx, &drops), 0);
  EXPECT_EQ(drops, 0u);

  char payload[512] = {};
  const int kSent = 200;
  for (int i = 0; i < kSent; ++i)
    ASSERT_EQ(sendto(tx, payload, sizeof payload, 0, reinterpret_cast<sockaddr*>(&a), sizeof a),
              static_cast<ssize_t>(sizeof payload));
  int received = 0;
  while (recv(rx, payload, sizeof payload, MSG_DONTWAIT) > 0) ++received;
  ASSERT_EQ(ccomm::platform::SocketDrops(rx, &drops), 0);
  EXPECT_GT(drops, 0u);
  EXPECT_EQ(static_cast<int>(drops) + received, kSent) << "received " << received << ", dropped " << drops;
  close(rx);
  close(tx);
}

TEST(SocketDrops, ReportsABadDescriptor) {
  uint32_t drops = 0;
  EXPECT_LT(ccomm::platform::SocketDrops(-1, &drops), 0);
}

TEST(StderrIsJournal, ComparesTheStreamWithStderr) {
  struct stat st;
  ASSERT_EQ(fstat(STDERR_FILENO, &st), 0);
  const std::string mine = std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  const std::string other = std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino + 1);
  ASSERT_EQ(unsetenv("JOURNAL_STREAM"), 0);
  EXPECT_FALSE(ccomm::platform::StderrIsJournal());
  ASSERT_EQ(setenv("JOURNAL_STREAM", mine.c_str(), 1), 0);
  EXPECT_TRUE(ccomm::platform::StderrIsJournal());
  ASSERT_EQ(setenv("JOURNAL_STREAM", other.c_str(), 1), 0);  // inherited, stderr redirected since
  EXPECT_FALSE(ccomm::platform::StderrIsJournal());
  ASSERT_EQ(setenv("JOURNAL_STREAM", (mine + "x").c_str(), 1), 0);
  EXPECT_FALSE(ccomm::platform::StderrIsJournal());
  ASSERT_EQ(setenv("JOURNAL_STREAM", "", 1), 0);
  EXPECT_FALSE(ccomm::platform::StderrIsJournal());
  unsetenv("JOURNAL_STREAM");
}

}  // namespace

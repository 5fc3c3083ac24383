// SPDX-License-Identifier: Apache-2.0
// Frame authentication: tag, key file rules, replay window, and a real Daemon on
// loopback UDP that must reject (and count) a wrong MAC, a replayed frame and a frame
// from an unknown node while accepting genuine ones.
#include "daemon/security/auth.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>
#include <thread>
#include <vector>

#include "common/platform.h"
#include "daemon/engine/daemon.h"
#include "testing/test_config.h"

namespace ccomm {
namespace {

using auth::FrameAuth;
using auth::ReplayVerdict;
using auth::ReplayWindow;

const uint8_t kKey[auth::kKeyBytes] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16,
                                       17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32};

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/ccomm-auth-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() {
    for (const auto& f : files_) unlink(f.c_str());
    rmdir(path_.c_str());
  }
  std::string Write(const std::string& name, const void* data, size_t len, mode_t mode) {
    std::string p = path_ + "/" + name;
    int fd = open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    EXPECT_GE(fd, 0);
    EXPECT_EQ(write(fd, data, len), static_cast<ssize_t>(len));
    fchmod(fd, mode);
    close(fd);
    files_.push_back(p);
    return p;
  }

 private:
  std::string path_;
  std::vector<std::string> files_;
};

// A frame from `sender` to `dest` with one double entry, tagged with `key` (none if null).
std::vector<uint8_t> MakeFrame(uint16_t sender, uint16_t dest, uint32_t hash, uint32_t seq,
                               uint64_t send_ns, uint16_t signal, uint32_t value_seq, double v,
                               const uint8_t* key) {
  std::vector<uint8_t> buf(wire::kMaxFrameSize);
  wire::FrameWriter w(buf.data(), buf.size());
  wire::FrameHeader h;
  h.flags = key ? wire::kFlagAuth : 0;
  h.sender = sender;
  h.dest = dest;
  h.config_hash = hash;
  h.seq = seq;
  h.send_time_ns = send_ns;
  w.Begin(h);
  EXPECT_TRUE(w.Add(signal, static_cast<uint8_t>(ValueType::kDouble), 0, 1, value_seq, send_ns, &v, 8));
  size_t len = w.Finish();
  EXPECT_GT(len, 0u);
  if (key) {
    FrameAuth a;
    a.SetKey(key);
    a.Sign(buf.data(), len, buf.data() + len);
    len += auth::kTagBytes;
  }
  buf.resize(len);
  return buf;
}

TEST(FrameAuth, TagVerifiesAndAnyChangeBreaksIt) {
  if (!auth::Available()) GTEST_SKIP() << "built without libsodium";
  FrameAuth a;
  a.SetKey(kKey);
  ASSERT_TRUE(a.enabled());
  auto f = MakeFrame(1, 0, 0x1234, 7, 1000, 0, 1, 2.5, kKey);
  wire::FrameHeader h;
  ASSERT_EQ(wire::DecodeHeader(f.data(), f.size(), &h), wire::DecodeError::kOk);
  EXPECT_TRUE(a.Accept(f.data(), f.size(), h.flags));
  for (size_t i = 0; i < f.size(); ++i) {  // every single bit of header, entries and tag
    for (int bit = 0; bit < 8; ++bit) {
      f[i] ^= static_cast<uint8_t>(1u << bit);
      EXPECT_FALSE(a.Accept(f.data(), f.size(), h.flags)) << "byte " << i << " bit " << bit;
      f[i] ^= static_cast<uint8_t>(1u << bit);
    }
  }
  // Another key, no tag at all, and a tagged frame at a node without a key.
  uint8_t other[auth::kKeyBytes];
  memcpy(other, kKey, sizeof other);
  other[31] ^= 1;
  FrameAuth b;
  b.SetKey(other);
  EXPECT_FALSE(b.Accept(f.data(), f.size(), h.flags));
  auto plain = MakeFrame(1, 0, 0x1234, 7, 1000, 0, 1, 2.5, nullptr);
  EXPECT_FALSE(a.Accept(plain.data(), plain.size(), 0));
  FrameAuth none;
  EXPECT_TRUE(none.Accept(plain.data(), plain.size(), 0));
  EXPECT_FALSE(none.Accept(f.data(), f.size(), wire::kFlagAuth));
}

TEST(FrameAuth, MatchesSpecPrimitive) {
  if (!auth::Available()) GTEST_SKIP() << "built without libsodium";
  // BLAKE2b keyed (RFC 7693: outlen 16, keylen 32) of "abc" with key 00..1f: pins the
  // primitive so that another implementation of the protocol can interoperate.
  uint8_t key[32];
  for (int i = 0; i < 32; ++i) key[i] = static_cast<uint8_t>(i);
  FrameAuth a;
  a.SetKey(key);
  uint8_t tag[16];
  const uint8_t msg[3] = {'a', 'b', 'c'};
  a.Sign(msg, sizeof msg, tag);
  char hex[33];
  for (int i = 0; i < 16; ++i) snprintf(hex + 2 * i, 3, "%02x", tag[i]);
  // Computed independently with Python's hashlib.blake2b(b"abc", key=bytes(range(32)), digest_size=16).
  EXPECT_STREQ(hex, "1a64be47e4729d951c302ee543f97cf3");
}

TEST(KeyFile, RawAndHexAccepted) {
  TempDir d;
  uint8_t key[auth::kKeyBytes];
  std::string err;
  std::string raw = d.Write("raw.key", kKey, sizeof kKey, 0600);
  ASSERT_EQ(auth::LoadKeyFile(raw, key, &err), 0) << err;
  EXPECT_EQ(memcmp(key, kKey, sizeof key), 0);
  std::string hex;
  for (uint8_t b : kKey) {
    char t[3];
    snprintf(t, sizeof t, "%02X", b);
    hex += t;
  }
  hex += "\n";
  std::string hp = d.Write("hex.key", hex.data(), hex.size(), 0400);
  memset(key, 0, sizeof key);
  ASSERT_EQ(auth::LoadKeyFile(hp, key, &err), 0) << err;
  EXPECT_EQ(memcmp(key, kKey, sizeof key), 0);
}

TEST(KeyFile, RefusedWhenOthersCanReadOrWrongSize) {
  TempDir d;
  uint8_t key[auth::kKeyBytes];
  std::string err;
  for (mode_t mode : {0640, 0604, 0620, 0610, 0644}) {
    std::string p = d.Write("k" + std::to_string(mode), kKey, sizeof kKey, mode);
    err.clear();
    EXPECT_EQ(auth::LoadKeyFile(p, key, &err), -EPERM) << std::oct << mode;
    EXPECT_NE(err.find("chmod 600"), std::string::npos) << err;
  }
  std::string shortk = d.Write("short.key", kKey, 31, 0600);
  EXPECT_EQ(auth::LoadKeyFile(shortk, key, &err), -EINVAL);
  std::string badhex(64, 'g');
  std::string bh = d.Write("badhex.key", badhex.data(), badhex.size(), 0600);
  EXPECT_EQ(auth::LoadKeyFile(bh, key, &err), -EINVAL);
  EXPECT_EQ(auth::LoadKeyFile(d.Write("long.key", std::string(100, 'a').data(), 100, 0600), key, &err),
            -EINVAL);
  EXPECT_EQ(auth::LoadKeyFile("/nonexistent/ccomm.key", key, &err), -ENOENT);
}

constexpr uint64_t kMs = 1000 * 1000;
constexpr uint64_t kTimeout = 300 * kMs;

TEST(ReplayWindow, InOrderDuplicateAndReordered) {
  ReplayWindow w;
  uint64_t now = 1000 * kMs;
  EXPECT_EQ(w.Check(10, 100, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(10, 100, now, kTimeout), ReplayVerdict::kReplay);
  EXPECT_EQ(w.Check(11, 110, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(14, 140, now, kTimeout), ReplayVerdict::kAccept);  // 12, 13 late
  EXPECT_EQ(w.Check(13, 130, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(13, 130, now, kTimeout), ReplayVerdict::kReplay);
  EXPECT_EQ(w.Check(12, 120, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(11, 110, now, kTimeout), ReplayVerdict::kReplay);
  // A frame ahead in seq but sent before the newest: recorded earlier, not new.
  EXPECT_EQ(w.Check(20, 125, now, kTimeout), ReplayVerdict::kReplay);
  // Older than the window: refused even if never seen.
  EXPECT_EQ(w.Check(200, 2000, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(200 - ReplayWindow::kWidth, 1990, now, kTimeout), ReplayVerdict::kReplay);
  EXPECT_EQ(w.Check(200 - ReplayWindow::kWidth + 1, 1990, now, kTimeout), ReplayVerdict::kAccept);
}

TEST(ReplayWindow, SequenceWrapsAround) {
  ReplayWindow w;
  EXPECT_EQ(w.Check(0xFFFFFFFEu, 1, 1, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(0xFFFFFFFFu, 2, 1, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(0, 3, 1, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(0xFFFFFFFFu, 2, 1, kTimeout), ReplayVerdict::kReplay);
}

TEST(ReplayWindow, RestartedSenderAcceptedButNotItsPastLife) {
  ReplayWindow w;
  uint64_t now = 5000 * kMs;
  for (uint32_t s = 0; s < 100; ++s) ASSERT_EQ(w.Check(s, 1000 + s, now, kTimeout), ReplayVerdict::kAccept);
  // ccommd restarted on the same board: seq back to 0, clock went on.
  EXPECT_EQ(w.Check(0, 5000, now, kTimeout), ReplayVerdict::kRestart);
  EXPECT_EQ(w.Check(1, 5001, now, kTimeout), ReplayVerdict::kAccept);
  // Frames recorded from the previous run: same or higher seq, older clock.
  EXPECT_EQ(w.Check(0, 1000, now, kTimeout), ReplayVerdict::kReplay);
  EXPECT_EQ(w.Check(3, 1003, now, kTimeout), ReplayVerdict::kReplay);  // in window by seq, but older
  EXPECT_EQ(w.Check(99, 1099, now, kTimeout), ReplayVerdict::kReplay);
  EXPECT_EQ(w.Check(2, 5002, now, kTimeout), ReplayVerdict::kAccept);
}

TEST(ReplayWindow, RebootedBoardOnlyAfterPlausibleSilence) {
  ReplayWindow w;
  uint64_t now = 100000 * kMs;
  // The peer has been up 60 s.
  for (uint32_t s = 0; s < 10; ++s)
    ASSERT_EQ(w.Check(5000 + s, 60000 * kMs + s * kMs, now, kTimeout), ReplayVerdict::kAccept);
  // While it is still talking, a frame with an old clock is a replay, whatever its seq.
  EXPECT_EQ(w.Check(0, 5 * kMs, now + 10 * kMs, kTimeout), ReplayVerdict::kReplay);
  // Silent for 20 s, then a frame claiming 30 s of uptime (older than the newest frame):
  // the board cannot have booted after its last frame, so it is a recording.
  now += 20000 * kMs;
  EXPECT_EQ(w.Check(0, 30000 * kMs, now, kTimeout), ReplayVerdict::kReplay);
  // Frames from a clock at 8 s: it rebooted 8 s ago, within the silence. Accept.
  EXPECT_EQ(w.Check(0, 8000 * kMs, now, kTimeout), ReplayVerdict::kRestart);
  EXPECT_EQ(w.Check(1, 8100 * kMs, now, kTimeout), ReplayVerdict::kAccept);
  EXPECT_EQ(w.Check(0, 8000 * kMs, now, kTimeout), ReplayVerdict::kReplay);
  // A short silence (below peer_timeout) never allows the clock to go back.
  EXPECT_EQ(w.Check(0, 1 * kMs, now + 200 * kMs, kTimeout), ReplayVerdict::kReplay);
}

// ---- A real daemon on loopback UDP -------------------------------------------------

class DaemonAuthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("CCOMM_SHM_PREFIX", testing::UniquePrefix("auth").c_str(), 1);
    // "sp" is produced by b (node 1) and consumed by a (node 0, the daemon under test).
    auto pos = testing::MakeSignal("pos", ValueType::kDouble, 1, SignalKind::kState, 0, {1});
    auto sp = testing::MakeSignal("sp", ValueType::kDouble, 1, SignalKind::kState, 1, {0});
    cfg_ = testing::TwoNodeConfig({pos, sp});
    cfg_.nodes[0].transport = cfg_.nodes[1].transport = TransportKind::kUdp;
    cfg_.network.udp_port = testing::FreeUdpPort();
    tx_ = socket(AF_INET, SOCK_DGRAM, 0);
    // Frames claim node b: send them from b's configured address (receiver rule 2).
    struct sockaddr_in src = {};
    src.sin_family = AF_INET;
    inet_pton(AF_INET, cfg_.nodes[1].ip.c_str(), &src.sin_addr);
    EXPECT_EQ(bind(tx_, reinterpret_cast<const sockaddr*>(&src), sizeof src), 0);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(cfg_.network.udp_port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  void TearDown() override {
    if (running_) {
      daemon_.RequestStop();
      rx_.join();
    }
    daemon_.Shutdown();
    close(tx_);
    platform::ShmUnlink(store::SegmentName("a").c_str());
  }
  int Start(std::string* err) {
    DaemonOptions opt;
    opt.no_realtime = true;
    opt.recv_timeout_ms = 20;
    int r = daemon_.Start(cfg_, 0, opt, err);
    if (r == 0) {
      rx_ = std::thread([this] { daemon_.RunRx(); });
      running_ = true;
    }
    return r;
  }
  void Send(const std::vector<uint8_t>& f) {
    ASSERT_EQ(sendto(tx_, f.data(), f.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_),
              static_cast<ssize_t>(f.size()));
  }
  uint64_t Counter(store::DaemonCounter c) {
    return daemon_.segment().header()->daemon_counters[c].load();
  }
  // Waits until the daemon has looked at `n` frames in total (every frame ends in
  // exactly one of these counters).
  void WaitHandled(uint64_t n) {
    for (int i = 0; i < 400; ++i) {
      uint64_t t = Counter(store::kFramesRx) + Counter(store::kFramesAuthFailed) +
                   Counter(store::kFramesReplayed) + Counter(store::kFramesUnknownSender) +
                   Counter(store::kFramesBad) + Counter(store::kFramesWrongHash) +
                   Counter(store::kFramesNotForUs);
      if (t >= n) return;
      usleep(5000);
    }
    FAIL() << "daemon did not handle " << n << " frames";
  }
  double Value(uint64_t* seq) {
    double v = 0;
    store::SlotMeta m;
    EXPECT_EQ(store::StateRead(daemon_.segment().state(1), &v, &m), store::StoreResult::kOk);
    *seq = m.value_seq;
    return v;
  }

  SystemConfig cfg_;
  Daemon daemon_;
  std::thread rx_;
  bool running_ = false;
  int tx_ = -1;
  struct sockaddr_in to_ = {};
};

TEST_F(DaemonAuthTest, WrongMacReplayAndUnknownNodeAreRejectedAndCounted) {
  if (!auth::Available()) GTEST_SKIP() << "built without libsodium";
  TempDir d;
  cfg_.network.auth_key_file = d.Write("auth.key", kKey, sizeof kKey, 0600);
  std::string err;
  ASSERT_EQ(Start(&err), 0) << err;
  const uint64_t t0 = platform::MonotonicNs();

  auto good = MakeFrame(1, 0, cfg_.hash, 0, t0, 1, 1, 1.5, kKey);
  Send(good);
  WaitHandled(1);
  EXPECT_EQ(Counter(store::kFramesRx), 1u);
  uint64_t seq = 0;
  EXPECT_EQ(Value(&seq), 1.5);

  // 1. Wrong MAC: a flipped tag bit, a frame signed with another key, no tag at all.
  auto bad = MakeFrame(1, 0, cfg_.hash, 1, t0 + 1, 1, 2, 99.0, kKey);
  bad.back() ^= 0x01;
  Send(bad);
  uint8_t other[auth::kKeyBytes];
  memcpy(other, kKey, sizeof other);
  other[0] ^= 0x80;
  Send(MakeFrame(1, 0, cfg_.hash, 2, t0 + 2, 1, 3, 99.0, other));
  Send(MakeFrame(1, 0, cfg_.hash, 3, t0 + 3, 1, 4, 99.0, nullptr));
  WaitHandled(4);
  EXPECT_EQ(Counter(store::kFramesAuthFailed), 3u);

  // 2. Replay: the genuine frame again, twice.
  Send(good);
  Send(good);
  WaitHandled(6);
  EXPECT_EQ(Counter(store::kFramesReplayed), 2u);

  // 3. Unknown node: a correctly signed frame from node 7 (not in the file) and one
  //    claiming to come from the receiver itself.
  Send(MakeFrame(7, 0, cfg_.hash, 0, t0 + 4, 1, 5, 99.0, kKey));
  Send(MakeFrame(0, 0, cfg_.hash, 0, t0 + 5, 1, 6, 99.0, kKey));
  WaitHandled(8);
  EXPECT_EQ(Counter(store::kFramesUnknownSender), 2u);

  // None of them changed the value; a new genuine frame still gets through.
  EXPECT_EQ(Value(&seq), 1.5);
  EXPECT_EQ(seq, 1u);
  Send(MakeFrame(1, 0, cfg_.hash, 1, t0 + 6, 1, 7, 2.5, kKey));
  WaitHandled(9);
  EXPECT_EQ(Counter(store::kFramesRx), 2u);
  EXPECT_EQ(Value(&seq), 2.5);
  EXPECT_EQ(Counter(store::kFramesAuthFailed), 3u);
  EXPECT_EQ(Counter(store::kFramesReplayed), 2u);
  EXPECT_EQ(Counter(store::kFramesUnknownSender), 2u);
}

TEST_F(DaemonAuthTest, WithoutKeyTaggedFramesAreRefused) {
  std::string err;
  ASSERT_EQ(Start(&err), 0) << err;
  const uint64_t t0 = platform::MonotonicNs();
  Send(MakeFrame(1, 0, cfg_.hash, 0, t0, 1, 1, 1.5, nullptr));
  WaitHandled(1);
  EXPECT_EQ(Counter(store::kFramesRx), 1u);
  if (auth::Available()) {
    Send(MakeFrame(1, 0, cfg_.hash, 1, t0 + 1, 1, 2, 2.5, kKey));
    WaitHandled(2);
    EXPECT_EQ(Counter(store::kFramesAuthFailed), 1u);
  }
  Send(MakeFrame(9, 0, cfg_.hash, 0, t0 + 2, 1, 3, 2.5, nullptr));
  WaitHandled(3);
  EXPECT_EQ(Counter(store::kFramesUnknownSender), 1u);
}

TEST_F(DaemonAuthTest, StartRefusesAKeyOthersCanRead) {
  TempDir d;
  cfg_.network.auth_key_file = d.Write("auth.key", kKey, sizeof kKey, 0644);
  std::string err;
  EXPECT_NE(Start(&err), 0);
  if (auth::Available()) EXPECT_NE(err.find("must not be accessible by group or others"), std::string::npos) << err;
  else EXPECT_NE(err.find("without libsodium"), std::string::npos) << err;
}

}  // namespace
}  // namespace ccomm

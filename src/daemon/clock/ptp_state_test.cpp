// SPDX-License-Identifier: Apache-2.0
// ptp4l's management messages (ptp_state.h): the query's bytes, answers parsed or refused,
// and the clock state machine (none, syncing, synced, lost) from the answers and silences.
#include "daemon/clock/ptp_state.h"

#include "daemon/clock/ptp_config.h"

#include <gtest/gtest.h>
#include <string.h>

#include <vector>

namespace ccomm {
namespace ptp {
namespace {

constexpr uint64_t kS = 1'000'000'000;

// A RESPONSE as ptp4l sends it: the GET's header with action RESPONSE and the data.
std::vector<uint8_t> Response(uint16_t id, const std::vector<uint8_t>& data) {
  std::vector<uint8_t> m(64);
  m.resize(BuildGet(m.data(), m.size(), id, 7));
  m[46] = 2;  // RESPONSE
  m.insert(m.end(), data.begin(), data.end());
  const size_t tlv_len = 2 + data.size();
  m[50] = static_cast<uint8_t>(tlv_len >> 8);
  m[51] = static_cast<uint8_t>(tlv_len);
  m[2] = static_cast<uint8_t>(m.size() >> 8);
  m[3] = static_cast<uint8_t>(m.size());
  return m;
}
std::vector<uint8_t> TimeStatus(int64_t offset, bool gm_present) {
  std::vector<uint8_t> d(50, 0);
  for (int i = 0; i < 8; ++i) d[static_cast<size_t>(i)] = static_cast<uint8_t>(static_cast<uint64_t>(offset) >> (56 - 8 * i));
  d[41] = gm_present ? 1 : 0;
  return Response(kIdTimeStatusNp, d);
}
std::vector<uint8_t> PortData(uint8_t state, int64_t path_delay_ns) {
  std::vector<uint8_t> d(26, 0);
  d[10] = state;
  const uint64_t scaled = static_cast<uint64_t>(path_delay_ns) << 16;
  for (int i = 0; i < 8; ++i) d[static_cast<size_t>(12 + i)] = static_cast<uint8_t>(scaled >> (56 - 8 * i));
  return Response(kIdPortDataSet, d);
}

TEST(PtpManagement, GetIsTheMessagePmcSends) {
  uint8_t m[64];
  ASSERT_EQ(BuildGet(m, sizeof m, kIdTimeStatusNp, 0x1234), 54u);
  EXPECT_EQ(m[0], 0x0D);  // management
  EXPECT_EQ(m[1], 2);     // PTP v2
  EXPECT_EQ(m[2] << 8 | m[3], 54);
  EXPECT_EQ(m[30] << 8 | m[31], 0x1234);
  for (int i = 34; i < 44; ++i) EXPECT_EQ(m[i], 0xFF) << i;  // every port of every clock
  EXPECT_EQ(m[44], 0);  // boundary hops 0: the local ptp4l only
  EXPECT_EQ(m[46], 0);  // GET
  EXPECT_EQ(m[48] << 8 | m[49], 1);  // MANAGEMENT TLV
  EXPECT_EQ(m[50] << 8 | m[51], 2);
  EXPECT_EQ(m[52] << 8 | m[53], 0xC000);
  EXPECT_EQ(m[4], 0);     // domain 0 unless told
  EXPECT_EQ(BuildGet(m, 53, kIdTimeStatusNp, 1), 0u);
  ASSERT_EQ(BuildGet(m, sizeof m, kIdPortDataSet, 1, 24), 54u);
  EXPECT_EQ(m[4], 24);
}

TEST(PtpManagement, AnswersAreParsedAndAnythingElseRefused) {
  Reply r;
  auto ts = TimeStatus(-1234, true);
  ASSERT_TRUE(ParseReply(ts.data(), ts.size(), &r));
  EXPECT_EQ(r.id, kIdTimeStatusNp);
  EXPECT_EQ(r.master_offset_ns, -1234);
  EXPECT_TRUE(r.gm_present);
  auto pd = PortData(kPortSlave, 2500);
  ASSERT_TRUE(ParseReply(pd.data(), pd.size(), &r));
  EXPECT_EQ(r.port_state, kPortSlave);
  EXPECT_EQ(r.mean_path_delay_ns, 2500);
  // Every truncation is refused, and so is a GET (not an answer), an error status TLV,
  // a length field longer than the datagram, another id.
  for (size_t n = 0; n < ts.size(); ++n) EXPECT_FALSE(ParseReply(ts.data(), n, &r)) << n;
  auto get = ts;
  get[46] = 0;
  EXPECT_FALSE(ParseReply(get.data(), get.size(), &r));
  auto err = ts;
  err[49] = 2;  // MANAGEMENT_ERROR_STATUS
  EXPECT_FALSE(ParseReply(err.data(), err.size(), &r));
  auto longer = ts;
  longer[3] = static_cast<uint8_t>(longer[3] + 1);
  EXPECT_FALSE(ParseReply(longer.data(), longer.size(), &r));
  auto other = Response(0x2001, std::vector<uint8_t>(40, 0));
  EXPECT_FALSE(ParseReply(other.data(), other.size(), &r));
}

void Feed(Monitor* m, const std::vector<uint8_t>& msg, uint64_t now) {
  Reply r;
  ASSERT_TRUE(ParseReply(msg.data(), msg.size(), &r));
  m->Answer(r, now);
}

TEST(PtpMonitor, StatesFollowPtp4l) {
  Monitor m;
  m.Configure("", 1000000, 0);
  uint64_t t = 100 * kS;
  EXPECT_FALSE(m.Evaluate(t));
  EXPECT_EQ(m.state(), ClockState::kNone);  // nobody ever answered
  Feed(&m, PortData(kPortListening, 0), t);
  Feed(&m, TimeStatus(0, false), t);
  EXPECT_TRUE(m.Evaluate(t));
  EXPECT_EQ(m.state(), ClockState::kSyncing);
  t += kS;
  Feed(&m, PortData(kPortUncalibrated, 0), t);
  Feed(&m, TimeStatus(50000000, true), t);
  m.Evaluate(t);
  EXPECT_EQ(m.state(), ClockState::kSyncing);
  t += kS;
  Feed(&m, PortData(kPortSlave, 0), t);
  Feed(&m, TimeStatus(5000000, true), t);  // a slave 5 ms off: not yet
  m.Evaluate(t);
  EXPECT_EQ(m.state(), ClockState::kSyncing);
  t += kS;
  Feed(&m, TimeStatus(-800, true), t);
  EXPECT_TRUE(m.Evaluate(t));
  EXPECT_EQ(m.state(), ClockState::kSynced);
  EXPECT_EQ(m.offset_ns(), -800);
  // ptp4l killed: still synced for two polls, then lost, and lost stays lost.
  EXPECT_FALSE(m.Evaluate(t + Monitor::kLostAfterNs));
  EXPECT_TRUE(m.Evaluate(t + Monitor::kLostAfterNs + 1));
  EXPECT_EQ(m.state(), ClockState::kLost);
  EXPECT_EQ(m.state(), ClockState::kLost);
  // It comes back as grandmaster (no other master): synced, its own reference.
  t += 10 * kS;
  Feed(&m, PortData(kPortMaster, 0), t);
  Feed(&m, TimeStatus(0, false), t);
  m.Evaluate(t);
  EXPECT_EQ(m.state(), ClockState::kSynced);
  Feed(&m, PortData(kPortFaulty, 0), t);
  m.Evaluate(t);
  EXPECT_EQ(m.state(), ClockState::kLost);
}

TEST(Ptp4lConfig, EachNodeItsRoleFromOneFile) {
  const char* xml =
      "<ccomm version=\"1\">\n"
      "  <node name=\"control\" interface=\"eth0\" ip=\"10.42.0.1\"/>\n"
      "  <node name=\"planner\" interface=\"enp2s0\" ip=\"10.42.0.2\" transport=\"udp\"/>\n"
      "  <node name=\"vision\" interface=\"eth1\" ip=\"10.42.0.3\"/>\n"
      "  <signal name=\"pos\" type=\"double\" producer=\"control\" consumers=\"vision\"/>\n"
      "  <clock domain=\"3\" grandmaster=\"vision, control\" sync_interval_log=\"-4\"/>\n"
      "</ccomm>\n";
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(ParseConfig(xml, "signals.xml", &cfg, &err)) << err;
  const std::string control = Ptp4lConfig(cfg, 0, &err), planner = Ptp4lConfig(cfg, 1, &err),
                    vision = Ptp4lConfig(cfg, 2, &err);
  EXPECT_NE(control.find("[global]\ndomainNumber 3\npriority1 101\ntime_stamping software\nlogSyncInterval -4\n"
                         "network_transport L2\nuds_address /var/run/ptp4l\n[eth0]\n"), std::string::npos) << control;
  EXPECT_EQ(control.find("slaveOnly"), std::string::npos);
  EXPECT_NE(vision.find("priority1 100\n"), std::string::npos) << vision;  // the first candidate wins
  EXPECT_NE(planner.find("priority1 255\nslaveOnly 1\n"), std::string::npos) << planner;
  EXPECT_NE(planner.find("network_transport UDPv4\n"), std::string::npos) << planner;
  EXPECT_NE(planner.find("[enp2s0]\n"), std::string::npos) << planner;

  SystemConfig none;
  ASSERT_TRUE(ParseConfig(std::string(xml).replace(std::string(xml).find("  <clock"), 75, ""), "signals.xml", &none,
                          &err)) << err;
  EXPECT_EQ(Ptp4lConfig(none, 0, &err), "");
  EXPECT_NE(err.find("no <clock> section"), std::string::npos) << err;
}

// A UDP node may omit interface=; ptp4l cannot run without one, so say so, not "[]".
TEST(Ptp4lConfig, NodeWithoutInterfaceIsAnError) {
  const char* xml =
      "<ccomm version=\"1\">\n"
      "  <node name=\"a\" ip=\"127.0.0.1\" transport=\"udp\"/>\n"
      "  <node name=\"b\" ip=\"127.0.0.2\" transport=\"udp\"/>\n"
      "  <signal name=\"s\" type=\"double\" producer=\"a\" consumers=\"b\"/>\n"
      "  <clock grandmaster=\"a\"/>\n"
      "</ccomm>\n";
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(ParseConfig(xml, "signals.xml", &cfg, &err)) << err;
  EXPECT_EQ(Ptp4lConfig(cfg, 1, &err), "");
  EXPECT_NE(err.find("signals.xml:3: node 'b' has no interface="), std::string::npos) << err;
}

}  // namespace
}  // namespace ptp
}  // namespace ccomm

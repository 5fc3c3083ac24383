// SPDX-License-Identifier: Apache-2.0
// Tests of valid configurations: value types, defaults, every setting, dist/ and examples/.
#include "config/config.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "config/config_test_util.h"

namespace ccomm {
namespace {

template <typename T>
T ElementAt(const SignalConfig& s, size_t i) {
  T v;
  EXPECT_EQ(s.safe_value.size(), s.count * sizeof(T));
  std::memcpy(&v, s.safe_value.data() + i * sizeof(T), sizeof(T));
  return v;
}

TEST(ValueTypes, NamesSizesAndParsing) {
  struct {
    ValueType t;
    const char* name;
    size_t size;
  } cases[] = {{ValueType::kBool, "bool", 1},   {ValueType::kInt32, "int32", 4},
               {ValueType::kUint32, "uint32", 4}, {ValueType::kInt64, "int64", 8},
               {ValueType::kFloat, "float", 4}, {ValueType::kDouble, "double", 8}};
  for (const auto& c : cases) {
    EXPECT_STREQ(ValueTypeName(c.t), c.name);
    EXPECT_EQ(ValueTypeSize(c.t), c.size);
    ValueType parsed = ValueType::kBool;
    EXPECT_TRUE(ParseValueType(c.name, &parsed));
    EXPECT_EQ(parsed, c.t);
  }
  ValueType t = ValueType::kInt32;
  EXPECT_FALSE(ParseValueType("dubble", &t));
  EXPECT_FALSE(ParseValueType("Double", &t));
  EXPECT_FALSE(ParseValueType("", &t));
  EXPECT_EQ(t, ValueType::kInt32);
  EXPECT_EQ(ValueTypeName(static_cast<ValueType>(0)), nullptr);
  EXPECT_EQ(ValueTypeName(static_cast<ValueType>(7)), nullptr);
}

TEST(Parse, MinimalConfigGetsDefaults) {
  SystemConfig cfg = MustParse(
      "<ccomm version=\"1\">\n"
      "  <node name=\"a\" interface=\"eth0\"/>\n"
      "  <signal name=\"x\" type=\"double\" producer=\"a\"/>\n"
      "</ccomm>\n");
  EXPECT_EQ(cfg.path, "test.xml");
  EXPECT_EQ(cfg.network.ethertype, 0x88B5);
  EXPECT_EQ(cfg.network.udp_port, 47800);
  EXPECT_EQ(cfg.network.heartbeat_ms, 100u);
  EXPECT_EQ(cfg.network.peer_timeout_ms, 300u);
  EXPECT_EQ(cfg.network.summary_ms, 1000u);
  EXPECT_EQ(cfg.network.auth_key_file, "");
  ASSERT_EQ(cfg.nodes.size(), 1u);
  const NodeConfig& n = cfg.nodes[0];
  EXPECT_EQ(n.name, "a");
  EXPECT_EQ(n.interface, "eth0");
  EXPECT_FALSE(n.has_mac);
  EXPECT_EQ(n.ip, "");
  EXPECT_EQ(n.multicast, "");
  EXPECT_EQ(n.transport, TransportKind::kRaw);
  EXPECT_TRUE(n.realtime.mlockall);
  EXPECT_EQ(n.realtime.priority, 0);
  EXPECT_EQ(n.realtime.cpu, -1);
  EXPECT_EQ(n.realtime.spin_us, 0u);
  EXPECT_EQ(n.line, 2);
  ASSERT_EQ(cfg.signals.size(), 1u);
  const SignalConfig& s = cfg.signals[0];
  EXPECT_EQ(s.name, "x");
  EXPECT_EQ(s.type, ValueType::kDouble);
  EXPECT_EQ(s.count, 1u);
  EXPECT_EQ(s.kind, SignalKind::kState);
  EXPECT_EQ(s.producer, 0u);
  EXPECT_TRUE(s.consumers.empty());  // local-only
  EXPECT_EQ(s.stale_after_ms, 0u);
  EXPECT_FALSE(s.has_safe_value);
  EXPECT_EQ(s.period_us, 0u);
  EXPECT_EQ(s.queue_depth, 64u);
  EXPECT_EQ(s.line, 3);
  EXPECT_EQ(s.value_bytes(), 8u);
}

TEST(Parse, EverySettingReachesTheModel) {
  SystemConfig cfg = MustParse(R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- comment before the root -->
<ccomm version="1" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
       xsi:noNamespaceSchemaLocation="signals.xsd">
  <network ethertype="0x88B6" udp_port="40000" heartbeat_ms="50"
           peer_timeout_ms="200" summary_ms="0" auth_key_file="/etc/ccomm/k&amp;y.key"/>
  <node name="ctl-1" interface="enp3s0" mac="02:AB:cd:00:00:01" ip="10.0.0.1"
        multicast="239.1.2.3" transport="udp">
    <realtime mlockall="false" priority="80" cpu="1" spin_us="200"/>
  </node>
  <node name="plan_2" interface="eth1" ip="10.0.0.2" transport="udp"/>
  <node name="view.3" ip="127.0.0.3" transport="udp"/>
  <signal name="pos" type="double" count="3" producer="ctl-1" consumers="view.3, plan_2"
          stale_after_ms="20" safe_value="1.5, -2 3e2" rate_hz="1000"/>
  <signal name="flags" type="bool" count="4" producer="plan_2" consumers="ctl-1"
          stale_after_ms="100" safe_value="true" period_ms="0.1"/>
  <signal name="mode" type="int32" producer="plan_2" consumers="ctl-1" stale_after_ms="1000"
          safe_value="-2147483648" rate_hz="3"/>
  <signal name="ticks" type="uint32" producer="ctl-1" stale_after_ms="1" safe_value="0xFFFFFFFF"/>
  <signal name="big" type="int64" count="2" producer="ctl-1" consumers="plan_2"
          stale_after_ms="1" safe_value="-9223372036854775808 9223372036854775807"/>
  <signal name="f" type="float" producer="view.3" consumers="ctl-1" stale_after_ms="120000"
          safe_value="0.25" period_ms="60000"/>
  <signal name="estop" type="bool" kind="event" producer="plan_2" consumers="view.3,ctl-1"
          queue_depth="16"/>
  <signal name="st" type="double" kind="state" producer="view.3"/>
</ccomm>
)");
  EXPECT_EQ(cfg.network.ethertype, 0x88B6);
  EXPECT_EQ(cfg.network.udp_port, 40000);
  EXPECT_EQ(cfg.network.heartbeat_ms, 50u);
  EXPECT_EQ(cfg.network.peer_timeout_ms, 200u);
  EXPECT_EQ(cfg.network.summary_ms, 0u);  // off
  EXPECT_EQ(cfg.network.auth_key_file, "/etc/ccomm/k&y.key");
  ASSERT_EQ(cfg.nodes.size(), 3u);
  const NodeConfig& n0 = cfg.nodes[0];
  EXPECT_EQ(n0.name, "ctl-1");
  EXPECT_EQ(n0.interface, "enp3s0");
  ASSERT_TRUE(n0.has_mac);
  const uint8_t mac[6] = {0x02, 0xab, 0xcd, 0, 0, 1};
  EXPECT_EQ(std::memcmp(n0.mac, mac, 6), 0);
  EXPECT_EQ(n0.ip, "10.0.0.1");
  EXPECT_EQ(n0.multicast, "239.1.2.3");
  EXPECT_EQ(n0.transport, TransportKind::kUdp);
  EXPECT_FALSE(n0.realtime.mlockall);
  EXPECT_EQ(n0.realtime.priority, 80);
  EXPECT_EQ(n0.realtime.cpu, 1);
  EXPECT_EQ(n0.realtime.spin_us, 200u);
  EXPECT_EQ(n0.line, 7);
  EXPECT_EQ(cfg.nodes[1].transport, TransportKind::kUdp);
  EXPECT_EQ(cfg.nodes[2].interface, "");
  EXPECT_EQ(cfg.FindNode("plan_2"), 1);
  EXPECT_EQ(cfg.FindNode("view.3"), 2);
  EXPECT_EQ(cfg.FindNode("nope"), -1);

  ASSERT_EQ(cfg.signals.size(), 8u);
  const SignalConfig& pos = cfg.signals[0];
  EXPECT_EQ(pos.count, 3u);
  EXPECT_EQ(pos.producer, 0u);
  EXPECT_EQ(pos.consumers, (std::vector<uint32_t>{2, 1}));  // file order kept
  EXPECT_EQ(pos.stale_after_ms, 20u);
  EXPECT_TRUE(pos.has_safe_value);
  EXPECT_EQ(ElementAt<double>(pos, 0), 1.5);
  EXPECT_EQ(ElementAt<double>(pos, 1), -2.0);
  EXPECT_EQ(ElementAt<double>(pos, 2), 300.0);
  EXPECT_EQ(pos.period_us, 1000u);
  EXPECT_EQ(pos.line, 13);

  const SignalConfig& flags = cfg.signals[1];
  EXPECT_EQ(flags.type, ValueType::kBool);
  EXPECT_EQ(flags.value_bytes(), 4u);
  EXPECT_EQ(flags.safe_value, (std::vector<uint8_t>{1, 1, 1, 1}));  // one value = all
  EXPECT_EQ(flags.period_us, 100u);

  const SignalConfig& mode = cfg.signals[2];
  EXPECT_EQ(ElementAt<int32_t>(mode, 0), INT32_MIN);
  EXPECT_EQ(mode.period_us, 333333u);  // 1 s / 3, rounded

  EXPECT_EQ(ElementAt<uint32_t>(cfg.signals[3], 0), 0xFFFFFFFFu);
  EXPECT_TRUE(cfg.signals[3].consumers.empty());
  EXPECT_EQ(ElementAt<int64_t>(cfg.signals[4], 0), INT64_MIN);
  EXPECT_EQ(ElementAt<int64_t>(cfg.signals[4], 1), INT64_MAX);
  EXPECT_EQ(ElementAt<float>(cfg.signals[5], 0), 0.25f);
  EXPECT_EQ(cfg.signals[5].period_us, 60000000u);

  const SignalConfig& estop = cfg.signals[6];
  EXPECT_EQ(estop.kind, SignalKind::kEvent);
  EXPECT_EQ(estop.queue_depth, 16u);
  EXPECT_EQ(estop.producer, 1u);
  EXPECT_EQ(estop.consumers, (std::vector<uint32_t>{2, 0}));
  EXPECT_FALSE(estop.has_safe_value);
  EXPECT_EQ(cfg.signals[7].kind, SignalKind::kState);
  EXPECT_EQ(cfg.FindSignal("estop"), 6);
  EXPECT_EQ(cfg.FindSignal("pos"), 0);
  EXPECT_EQ(cfg.FindSignal("Pos"), -1);
  EXPECT_NE(cfg.hash, 0u);
}

TEST(Parse, DistSignalsXmlIsTheSetupSimulation) {
  SystemConfig cfg;
  std::string err;
  const std::string path = kSourceDir + "/dist/signals.xml";
  ASSERT_TRUE(LoadConfig(path, &cfg, &err)) << err;
  EXPECT_EQ(cfg.path, path);
  EXPECT_EQ(cfg.network.ethertype, 0x88B5);
  EXPECT_EQ(cfg.network.udp_port, 47800);
  ASSERT_EQ(cfg.nodes.size(), 2u);
  const int control = cfg.FindNode("control");
  const int planner = cfg.FindNode("planner");
  ASSERT_GE(control, 0);
  ASSERT_GE(planner, 0);
  // Thesis section 6.2.2: 36 doubles from the control board, 9 back.
  int to_planner = 0, to_control = 0;
  for (const SignalConfig& s : cfg.signals) {
    EXPECT_EQ(s.type, ValueType::kDouble) << s.name;
    EXPECT_EQ(s.count, 1u) << s.name;
    EXPECT_EQ(s.kind, SignalKind::kState) << s.name;
    ASSERT_EQ(s.consumers.size(), 1u) << s.name;
    if (s.producer == static_cast<uint32_t>(control)) {
      EXPECT_EQ(s.consumers[0], static_cast<uint32_t>(planner));
      ++to_planner;
    } else {
      EXPECT_EQ(s.producer, static_cast<uint32_t>(planner));
      EXPECT_EQ(s.consumers[0], static_cast<uint32_t>(control));
      ASSERT_TRUE(s.has_safe_value) << s.name;
      EXPECT_EQ(ElementAt<double>(s, 0), 0.0);
      ++to_control;
    }
  }
  EXPECT_EQ(to_planner, 36);
  EXPECT_EQ(to_control, 9);
  EXPECT_EQ(cfg.FindSignal("wheel0_pos"), 0);
}

TEST(Examples, AllExamplesAreValid) {
  std::vector<std::string> files = XmlFilesIn(kSourceDir + "/examples");
  ASSERT_GE(files.size(), 5u);
  for (const std::string& f : files) {
    SystemConfig cfg;
    std::string err;
    EXPECT_TRUE(LoadConfig(f, &cfg, &err)) << err;
  }
}

TEST(Examples, SingleSignalIsOneDoubleFromClientToServer) {
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(LoadConfig(kSourceDir + "/examples/single-signal.xml", &cfg, &err)) << err;
  ASSERT_EQ(cfg.signals.size(), 1u);
  const SignalConfig& s = cfg.signals[0];
  EXPECT_EQ(s.type, ValueType::kDouble);
  EXPECT_EQ(s.count, 1u);
  EXPECT_EQ(cfg.nodes[s.producer].name, "client");
  ASSERT_EQ(s.consumers.size(), 1u);
  EXPECT_EQ(cfg.nodes[s.consumers[0]].name, "server");
}

TEST(Examples, UdpVariantDiffersOnlyInTransport) {
  SystemConfig raw, udp;
  std::string err;
  ASSERT_TRUE(LoadConfig(kSourceDir + "/examples/setup-simulation.xml", &raw, &err)) << err;
  ASSERT_TRUE(LoadConfig(kSourceDir + "/examples/setup-simulation-udp.xml", &udp, &err)) << err;
  ASSERT_EQ(raw.nodes.size(), udp.nodes.size());
  ASSERT_EQ(raw.signals.size(), 45u);
  ASSERT_EQ(raw.signals.size(), udp.signals.size());
  for (size_t i = 0; i < raw.nodes.size(); ++i) {
    EXPECT_EQ(raw.nodes[i].transport, TransportKind::kRaw);
    EXPECT_EQ(udp.nodes[i].transport, TransportKind::kUdp);
  }
  for (size_t i = 0; i < raw.signals.size(); ++i) EXPECT_EQ(raw.signals[i].name, udp.signals[i].name);
  // Transport is not part of the hash: what is exchanged is identical.
  EXPECT_EQ(raw.hash, udp.hash);
}

TEST(Examples, LocalOnlyHasOneNodeAndNoForwardedSignal) {
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(LoadConfig(kSourceDir + "/examples/local-only.xml", &cfg, &err)) << err;
  EXPECT_EQ(cfg.nodes.size(), 1u);
  ASSERT_FALSE(cfg.signals.empty());
  for (const SignalConfig& s : cfg.signals) EXPECT_TRUE(s.consumers.empty()) << s.name;
}

TEST(Examples, ArraysAndEventsExampleHasBoth) {
  SystemConfig cfg;
  std::string err;
  ASSERT_TRUE(LoadConfig(kSourceDir + "/examples/arrays-and-events.xml", &cfg, &err)) << err;
  bool array = false, event = false;
  for (const SignalConfig& s : cfg.signals) {
    array |= s.count > 1;
    event |= s.kind == SignalKind::kEvent;
  }
  EXPECT_TRUE(array);
  EXPECT_TRUE(event);
}

}  // namespace
}  // namespace ccomm

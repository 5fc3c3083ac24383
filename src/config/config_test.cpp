// SPDX-License-Identifier: Apache-2.0
// Tests for the signals.xml parser: the model it builds, the config hash, and one case per
// malformed file under testdata/bad/ (each file states the errors it must produce).
#include "config/config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace ccomm {
namespace {

namespace fs = std::filesystem;

// $CCOMM_SOURCE_DIR first: on a target (ptest) the test data is installed elsewhere.
const std::string kSourceDir = getenv("CCOMM_SOURCE_DIR") ? getenv("CCOMM_SOURCE_DIR") : CCOMM_SOURCE_DIR;

std::string ReadFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::vector<std::string> Lines(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string line;
  while (std::getline(ss, line)) out.push_back(line);
  return out;
}

// Parses `xml`, expecting success; returns the model.
SystemConfig MustParse(const std::string& xml) {
  SystemConfig cfg;
  std::string err;
  EXPECT_TRUE(ParseConfig(xml, "test.xml", &cfg, &err)) << err << "\n--- input:\n" << xml;
  return cfg;
}

// Parses `xml`, expecting failure; returns the error text.
std::string MustFail(const std::string& xml) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(ParseConfig(xml, "test.xml", &cfg, &err)) << "accepted:\n" << xml;
  return err;
}

// Two raw nodes a, b and the given extra lines inside <ccomm>.
std::string TwoNodes(const std::string& body) {
  return "<ccomm version=\"1\">\n"
         "  <node name=\"a\" interface=\"eth0\"/>\n"
         "  <node name=\"b\" interface=\"eth0\"/>\n" +
         body + "\n</ccomm>\n";
}

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

std::vector<std::string> XmlFilesIn(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".xml") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
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

// ------------------------------------------------------------------------- hash

const char* kHashBase = R"(<ccomm version="1">
  <network ethertype="0x88B5" udp_port="47800"/>
  <node name="client" interface="eth0"/>
  <node name="server" interface="eth0"/>
  <node name="logger" interface="eth0"/>
  <node name="spare" interface="eth0"/>
  <signal name="value" type="double" producer="client" consumers="server,logger"/>
  <signal name="cmd" type="int32" count="4" kind="event" producer="server" consumers="client"/>
</ccomm>
)";

uint32_t HashOf(const std::string& xml) { return MustParse(xml).hash; }

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  size_t p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  if (p != std::string::npos) s.replace(p, from.size(), to);
  return s;
}

TEST(Hash, MatchesTheDocumentedCanonicalForm) {
  // Computed independently (Python) from the canonical form in docs/config.md:
  //   ccomm-config 1\nnetwork 34997 47800\nnode client\nnode server\nnode logger\n
  //   node spare\n
  //   signal value double 1 state client server,logger\n
  //   signal cmd int32 4 event server client\n
  EXPECT_EQ(HashOf(kHashBase), 0x35465836u);
}

TEST(Hash, IgnoresLayoutCommentsAndLocalPolicy) {
  const uint32_t base = HashOf(kHashBase);
  const std::string b = kHashBase;
  // Whitespace, comments, attribute order, quoting style, consumer order.
  EXPECT_EQ(HashOf("<!-- c -->\n" + Replace(b, "<node name=\"client\" interface=\"eth0\"/>",
                                            "<node   interface='eth0'\n\n name='client' >"
                                            "<!-- x --></node>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"", "consumers=\" logger , server\"")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"", "consumers=\"logger\tserver\"")),
            base);
  // Local policy: staleness, safe values, periods, realtime, addresses, transport.
  EXPECT_EQ(HashOf(Replace(b, "consumers=\"server,logger\"",
                           "consumers=\"server,logger\" stale_after_ms=\"20\" safe_value=\"1\" "
                           "period_ms=\"2\"")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "<node name=\"server\" interface=\"eth0\"/>",
                           "<node name=\"server\" interface=\"eth1\" ip=\"10.0.0.2\" "
                           "mac=\"02:00:00:00:00:02\" history=\"1024\"><realtime priority=\"90\"/></node>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "<network ethertype=\"0x88B5\" udp_port=\"47800\"/>",
                           "<network ethertype=\"34997\" udp_port=\"47800\" heartbeat_ms=\"10\" "
                           "peer_timeout_ms=\"50\"/>")),
            base);
  EXPECT_EQ(HashOf(Replace(b, "kind=\"event\"", "kind=\"event\" queue_depth=\"1024\"")), base);
}

TEST(Hash, ChangesWithWhatBothEndsMustAgreeOn) {
  const uint32_t base = HashOf(kHashBase);
  const std::string b = kHashBase;
  const std::vector<std::pair<std::string, std::string>> changes = {
      {"type=\"double\"", "type=\"float\""},
      {"type=\"int32\"", "type=\"uint32\""},
      {"count=\"4\"", "count=\"5\""},
      {"kind=\"event\"", "kind=\"state\""},
      {"name=\"value\"", "name=\"value2\""},
      {"producer=\"client\"", "producer=\"spare\""},
      {"consumers=\"server,logger\"", "consumers=\"server\""},
      {"consumers=\"client\"", "consumers=\"client,logger\""},
      {"<node name=\"logger\"", "<node name=\"logger2\""},
      {"udp_port=\"47800\"", "udp_port=\"47801\""},
      {"ethertype=\"0x88B5\"", "ethertype=\"0x88B6\""},
  };
  for (const auto& [from, to] : changes) {
    std::string xml = Replace(b, from, to);
    if (to.find("logger2") != std::string::npos)
      xml = Replace(xml, "consumers=\"server,logger\"", "consumers=\"server,logger2\"");
    EXPECT_NE(HashOf(xml), base) << from << " -> " << to;
  }
  // Node order and signal order define the ids.
  std::string swapped_nodes =
      Replace(b, "<node name=\"client\" interface=\"eth0\"/>\n  <node name=\"server\" "
                 "interface=\"eth0\"/>",
                 "<node name=\"server\" interface=\"eth0\"/>\n  <node name=\"client\" "
                 "interface=\"eth0\"/>");
  EXPECT_NE(HashOf(swapped_nodes), base);
  const std::string sig1 =
      "<signal name=\"value\" type=\"double\" producer=\"client\" consumers=\"server,logger\"/>";
  const std::string sig2 =
      "<signal name=\"cmd\" type=\"int32\" count=\"4\" kind=\"event\" producer=\"server\" "
      "consumers=\"client\"/>";
  std::string swapped_signals = Replace(Replace(b, sig1, "@1"), sig2, sig1);
  swapped_signals = Replace(swapped_signals, "@1", sig2);
  EXPECT_NE(HashOf(swapped_signals), base);
}

// ------------------------------------------------------------- inline edge cases

struct EdgeCase {
  const char* signal_attrs;  // attributes of one <signal name="s" ...> produced by a for b
  const char* error;         // nullptr = must be accepted; else a fragment of the error
};

TEST(Parse, SignalAttributeEdgeCases) {
  const EdgeCase cases[] = {
      {R"(type="bool" count="65535")", nullptr},
      {R"(type="double" count="8192")", nullptr},
      {R"(type="double" count="8193")", "65544 bytes"},
      {R"(type="bool" count="65536")", "count 65536 out of range (expected 1..65535)"},
      {R"(type="double" count="8192" kind="event" queue_depth="1024")", nullptr},
      {R"(type="double" count="8192" kind="event" queue_depth="2048")",
       "queue_depth 2048 x 65536-byte values is more than 64 MiB of queue: at most 1024 values of this size"},
      {R"(type="bool" count="0")", "count 0 out of range"},
      {R"(type="bool" count="-1")", "invalid count '-1'"},
      {R"(type="bool" count="4x")", "invalid count '4x'"},
      {R"(type="bool" count="0x10")", "invalid count '0x10'"},
      {R"(type="bool" count="010")", nullptr},  // decimal, not octal
      {R"(type="uint32" stale_after_ms="1" safe_value="0x8000_0000")", "invalid safe_value"},
      {R"(type="int32" stale_after_ms="1" safe_value="-0x80000000")", nullptr},
      {R"(type="int32" stale_after_ms="1" safe_value="-0x80000001")", "out of range"},
      {R"(type="bool" count=" 4")", "invalid count ' 4'"},
      {R"(type="bool" count="99999999999999999999999")", "out of range"},
      {R"(type="double" period_ms="0.05")", nullptr},
      {R"(type="double" period_ms="0.049")", "period of 49 us"},
      {R"(type="double" period_ms="0.0500")", nullptr},
      {R"(type="double" period_ms="0.0505")", "invalid period_ms '0.0505'"},
      {R"(type="double" period_ms="1.")", "invalid period_ms"},
      {R"(type="double" period_ms=".5")", "invalid period_ms"},
      {R"(type="double" period_ms="-1")", "invalid period_ms"},
      {R"(type="double" period_ms="0")", "period_ms 0 out of range"},
      {R"(type="double" period_ms="60000.001")", "period of 60000001 us"},
      {R"(type="double" rate_hz="20000")", nullptr},
      {R"(type="double" rate_hz="20001")", nullptr},  // 49.9975 us rounds to 50
      {R"(type="double" rate_hz="20500")", "period of 49 us"},
      {R"(type="double" rate_hz="25000")", "period of 40 us"},
      {R"(type="double" rate_hz="0.01")", "period of 100000000 us"},
      {R"(type="double" rate_hz="1e3")", "invalid rate_hz"},
      {R"(type="double" rate_hz="100" period_ms="10")", "both period_ms and rate_hz"},
      {R"(type="double" stale_after_ms="3600000")", nullptr},
      {R"(type="double" stale_after_ms="3600001")", "out of range (expected 0..3600000)"},
      {R"(type="double" stale_after_ms="10" period_ms="10")", "not longer than the period"},
      {R"(type="double" stale_after_ms="11" period_ms="10")", nullptr},
      {R"(type="double" safe_value="1")", nullptr},  // the value until the first arrives
      {R"(type="double" stale_after_ms="0" safe_value="1")", nullptr},
      {R"(type="double" kind="event" safe_value="1")", "applies only to state signals"},
      {R"(type="double" stale_after_ms="5" safe_value="nan")", nullptr},
      {R"(type="double" stale_after_ms="5" safe_value="1e400")", "out of range for type double"},
      {R"(type="double" stale_after_ms="5" safe_value="+1")", "invalid safe_value '+1'"},
      {R"(type="double" stale_after_ms="5" safe_value="1,5")", "2 values"},
      {R"(type="double" stale_after_ms="5" safe_value="")", "empty safe_value"},
      {R"(type="double" count="2" stale_after_ms="5" safe_value="1,,2")", "empty element"},
      {R"(type="double" count="2" stale_after_ms="5" safe_value="1,2,")", "empty element"},
      {R"(type="double" count="3" stale_after_ms="5" safe_value=" 1 2,3 ")", nullptr},
      {R"(type="float" stale_after_ms="5" safe_value="3.5e38")", "out of range for type float"},
      {R"(type="int32" stale_after_ms="5" safe_value="2147483648")", "out of range for type int32"},
      {R"(type="int32" stale_after_ms="5" safe_value="1.5")", "invalid safe_value '1.5'"},
      {R"(type="uint32" stale_after_ms="5" safe_value="-1")", "out of range for type uint32"},
      {R"(type="uint32" stale_after_ms="5" safe_value="4294967296")", "out of range for type uint32"},
      {R"(type="int64" stale_after_ms="5" safe_value="9223372036854775808")", "out of range"},
      {R"(type="bool" stale_after_ms="5" safe_value="yes")", "expected true, false, 1 or 0"},
      {R"(type="bool" stale_after_ms="5" safe_value="0")", nullptr},
      {R"(type="bool" kind="event" queue_depth="2")", nullptr},
      {R"(type="bool" kind="event" queue_depth="65536")", nullptr},
      {R"(type="bool" kind="event" queue_depth="131072")", "out of range (expected 2..65536)"},
      {R"(type="bool" kind="event" queue_depth="1")", "out of range"},
      {R"(type="bool" kind="event" queue_depth="48")", "not a power of two"},
      {R"(type="bool" queue_depth="16")", "only to event signals"},
      {R"(type="bool" kind="event" stale_after_ms="5")", "only to state signals"},
      {R"(type="bool" kind="event" period_ms="5")", "only to state signals"},
      {R"(type="bool" kind="Event")", "unknown kind 'Event' (expected state or event)"},
      {R"(type="bool" name2="x")", "unknown attribute 'name2'"},
      {R"(type="bool" consumers="b" consumers="b")", "duplicate attribute 'consumers'"},
      {R"(type="bool" consumers=",b")", "empty name in consumers"},
  };
  for (const EdgeCase& c : cases) {
    const std::string attrs = c.signal_attrs;
    const std::string consumers =
        attrs.find("consumers=") == std::string::npos ? "consumers=\"b\" " : "";
    std::string xml =
        TwoNodes("  <signal name=\"s\" producer=\"a\" " + consumers + attrs + "/>");
    SystemConfig cfg;
    std::string err;
    bool ok = ParseConfig(xml, "t.xml", &cfg, &err);
    if (c.error == nullptr) {
      EXPECT_TRUE(ok) << c.signal_attrs << ": " << err;
    } else {
      EXPECT_FALSE(ok) << c.signal_attrs;
      EXPECT_NE(err.find(c.error), std::string::npos) << c.signal_attrs << ": got " << err;
      EXPECT_EQ(err.rfind("t.xml:4: error: ", 0), 0u) << err;
    }
  }
}

TEST(Parse, NetworkAndNodeEdgeCases) {
  struct {
    const char* xml_fragment;  // replaces the first node line
    const char* error;
  } cases[] = {
      {R"(<network ethertype="0x0600"/><node name="a" interface="eth0"/>)", nullptr},
      {R"(<network ethertype="0x05FF"/><node name="a" interface="eth0"/>)", "ethertype 0x05FF out of range"},
      {R"(<network ethertype="0x10000"/><node name="a" interface="eth0"/>)", "out of range"},
      {R"(<network udp_port="0"/><node name="a" interface="eth0"/>)", "udp_port 0 out of range (expected 1..65535)"},
      {R"(<network summary_ms="fast"/><node name="a" interface="eth0"/>)",
       "invalid summary_ms 'fast' (expected an integer 0..60000)"},
      {R"(<network summary_ms="60001"/><node name="a" interface="eth0"/>)",
       "summary_ms 60001 out of range (expected 0..60000)"},
      {R"(<network udp_port="65535"/><node name="a" interface="eth0"/>)", nullptr},
      {R"(<network heartbeat_ms="200"/><node name="a" interface="eth0"/>)", "less than twice"},
      {R"(<network auth_key_file="key"/><node name="a" interface="eth0"/>)", "not an absolute path"},
      {R"(<node name="a" interface="eth0"><realtime priority="99" cpu="0" spin_us="100000"/></node>)", nullptr},
      {R"(<node name="a" interface="eth0"><realtime priority="0"/></node>)", "priority 0 out of range (expected 1..99)"},
      {R"(<node name="a" interface="eth0"><realtime priority="100"/></node>)", "priority 100 out of range"},
      {R"(<node name="a" interface="eth0"><realtime cpu="-1"/></node>)", "cpu -1 out of range"},
      {R"(<node name="a" interface="eth0"><realtime mlockall="yes"/></node>)", "invalid mlockall 'yes'"},
      {R"(<node name="a" interface="eth0"><realtime/><realtime/></node>)", "second <realtime>"},
      {R"(<node name="a" interface="eth0"><rt/></node>)", "unknown element <rt> in <node>"},
      {R"(<node name="a" interface="eth0">text</node>)", "unexpected text 'text'"},
      {R"(<node name="a" interface="eth0" mac="02:00:00:00:00:0g"/>)", "invalid mac"},
      {R"(<node name="a" interface="eth0" mac="02-00-00-00-00-01"/>)", "invalid mac"},
      {R"(<node name="a" interface="eth0" mac="ff:ff:ff:ff:ff:ff"/>)", "broadcast"},
      {R"(<node name="a" interface="eth0" mac="01:00:5e:00:00:01"/>)", "multicast"},
      {R"(<node name="a" interface="eth0" ip="10.0.0.256"/>)", "invalid ip '10.0.0.256'"},
      {R"(<node name="a" interface="eth0" ip="10.0.0"/>)", "invalid ip"},
      {R"(<node name="a" interface="eth0" ip="10.0.0.01"/>)", "invalid ip"},
      {R"(<node name="a" interface="eth0" ip="10.0.0.1 "/>)", "invalid ip"},
      {R"(<node name="a" interface="eth0" ip="239.0.0.1"/>)", "not a unicast address"},
      {R"(<node name="a" interface="eth0" multicast="239.255.255.255"/>)", nullptr},
      {R"(<node name="a" interface="eth0" multicast="240.0.0.1"/>)", "not in 224.0.0.0/4"},
      {R"(<node name="a" interface="eth0" multicast="223.255.255.255"/>)", "not in 224.0.0.0/4"},
      {R"(<node name="a" interface="eth0" history="256"/>)", nullptr},
      {R"(<node name="a" interface="eth0" history="65536"/>)", nullptr},
      {R"(<node name="a" interface="eth0" history="100"/>)", "history 100 is not a power of two"},
      {R"(<node name="a" interface="eth0" history="1"/>)", "out of range"},
      {R"(<node name="a" interface="eth0" history="131072"/>)", "out of range"},
      {R"(<node name="a" interface="a-very-long-name0"/>)", "invalid interface name"},
      {R"(<node name="a" interface="eth0:1"/>)", "invalid interface name"},
      {R"(<node name="a"/>)", "raw node 'a' needs interface="},
      {R"(<node name="a" transport="udp"/>)", "udp node 'a' needs ip="},
      {R"(<node name="a" transport="UDP"/>)", "unknown transport 'UDP' (expected raw or udp)"},
      {R"(<node name="a" interface="eth0" ip="10.0.0.1"/><node name="c" ip="10.0.0.1" transport="udp"/>)", "same ip"},
      {R"(<node name="a" interface="eth0" mac="02:00:00:00:00:01"/><node name="c" interface="eth0" mac="02:00:00:00:00:01"/>)", "same mac"},
      {R"(<node name="a" interface="eth0"/><node name="a" interface="eth1"/>)", "duplicate node name 'a' (first defined at line 2)"},
      {R"(<node name="a b" interface="eth0"/>)", "invalid character ' ' in node name 'a b'"},
      {R"(<node name="-a" interface="eth0"/>)", "must not start with '.' or '-'"},
      {R"(<node name="" interface="eth0"/>)", "empty node name"},
      {R"(<node interface="eth0"/>)", "<node> without name="},
      {R"(<node name="a&#x41;" interface="eth0"/>)", nullptr},  // "aA"
      {R"(<node name="a&nbsp;" interface="eth0"/>)", "invalid entity reference '&nbsp;'"},
  };
  for (const auto& c : cases) {
    std::string xml = std::string("<ccomm version=\"1\">\n") + c.xml_fragment +
                      "\n  <node name=\"b\" interface=\"eth0\"/>\n</ccomm>\n";
    SystemConfig cfg;
    std::string err;
    bool ok = ParseConfig(xml, "t.xml", &cfg, &err);
    if (c.error == nullptr) {
      EXPECT_TRUE(ok) << c.xml_fragment << ": " << err;
    } else {
      EXPECT_FALSE(ok) << c.xml_fragment;
      EXPECT_NE(err.find(c.error), std::string::npos) << c.xml_fragment << ": got " << err;
      EXPECT_EQ(err.rfind("t.xml:2: error: ", 0), 0u) << err;
    }
  }
}

TEST(Parse, NameLengthLimit) {
  const std::string ok(kMaxNameLength, 'n');
  MustParse(TwoNodes("<signal name=\"" + ok + "\" type=\"bool\" producer=\"a\"/>"));
  std::string err = MustFail(TwoNodes("<signal name=\"" + ok + "x\" type=\"bool\" producer=\"a\"/>"));
  EXPECT_NE(err.find("is 64 characters long (at most 63)"), std::string::npos) << err;
}

TEST(Parse, LimitsOnNodesAndSignals) {
  std::string nodes;
  for (uint32_t i = 0; i < kMaxNodes; ++i)
    nodes += "<node name=\"n" + std::to_string(i) + "\" interface=\"eth0\"/>\n";
  std::string signals;
  for (uint32_t i = 0; i < kMaxSignals; ++i)
    signals += "<signal name=\"s" + std::to_string(i) + "\" type=\"bool\" producer=\"n0\" consumers=\"n1\"/>\n";
  SystemConfig cfg = MustParse("<ccomm version=\"1\">\n" + nodes + signals + "</ccomm>\n");
  EXPECT_EQ(cfg.nodes.size(), kMaxNodes);
  EXPECT_EQ(cfg.signals.size(), kMaxSignals);
  EXPECT_EQ(cfg.FindSignal("s4095"), 4095);

  std::string err = MustFail("<ccomm version=\"1\">\n" + nodes +
                             "<node name=\"extra\" interface=\"eth0\"/>\n" + signals + "</ccomm>\n");
  EXPECT_NE(err.find("test.xml:66: error: too many nodes (at most 64)"), std::string::npos) << err;
  err = MustFail("<ccomm version=\"1\">\n" + nodes + signals +
                 "<signal name=\"extra\" type=\"bool\" producer=\"n0\"/>\n</ccomm>\n");
  EXPECT_NE(err.find(":" + std::to_string(2 + kMaxNodes + kMaxSignals) +
                     ": error: too many signals (at most 4096)"),
            std::string::npos)
      << err;
}

TEST(Parse, ErrorsAreCappedAndSortedByLine) {
  std::string signals;
  for (int i = 0; i < 200; ++i)
    signals += "<signal name=\"s" + std::to_string(i) + "\" type=\"dubble\" producer=\"nobody\"/>\n";
  std::string err = MustFail(TwoNodes(signals));
  std::vector<std::string> lines = Lines(err);
  ASSERT_EQ(lines.size(), 51u);
  EXPECT_EQ(lines.back(), "test.xml: error: too many errors; stopped after 50");
  // Two errors per signal (type, producer), in line order, from line 4 on.
  EXPECT_EQ(lines[0].rfind("test.xml:4: error: unknown type 'dubble'", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("test.xml:4: error: unknown producer node 'nobody'", 0), 0u) << lines[1];
  EXPECT_EQ(lines[49].rfind("test.xml:28: error: ", 0), 0u) << lines[49];
}

TEST(Parse, FailureLeavesOutputUntouched) {
  SystemConfig cfg;
  cfg.path = "sentinel";
  cfg.hash = 42;
  std::string err;
  EXPECT_FALSE(ParseConfig("<ccomm version=\"1\"><node name=\"a\" transport=\"tcp\"/></ccomm>",
                           "x.xml", &cfg, &err));
  EXPECT_EQ(cfg.path, "sentinel");
  EXPECT_EQ(cfg.hash, 42u);
  EXPECT_TRUE(cfg.nodes.empty());
  // A null error pointer is allowed.
  EXPECT_FALSE(ParseConfig("<ccomm", "x.xml", &cfg, nullptr));
}

TEST(Parse, SyntaxErrorsCarryTheLine) {
  std::string err = MustFail("<ccomm version=\"1\">\n  <node name=\"a\" interface=\"eth0\"/>\n"
                             "  <signal name=\"x\" type=\"double\n producer=\"a\"/>\n</ccomm>\n");
  EXPECT_EQ(err.rfind("test.xml:4: error: XML syntax error: ", 0), 0u) << err;
  err = MustFail("");
  EXPECT_EQ(err, "test.xml:1: error: no root element (expected <ccomm version=\"1\">)");
  err = MustFail(std::string("<ccomm version=\"1\">\n\0</ccomm>", 28));
  EXPECT_EQ(err, "test.xml:2: error: NUL byte in file (not a text file?)");
  err = MustFail("<ccomm version=\"1\"><node name=\"a\" interface=\"eth0\"></nod></ccomm>");
  EXPECT_NE(err.find("XML syntax error: invalid closing tag name"), std::string::npos) << err;
}

TEST(Parse, DeepNestingIsRefusedNotRecursed) {
  // A million levels would overflow the stack inside RapidXML if it were parsed.
  std::string deep = "<ccomm version=\"1\">\n";
  for (int i = 0; i < 1000000; ++i) deep += "<node>";
  std::string err = MustFail(deep);
  EXPECT_EQ(err, "test.xml:2: error: elements nested more than 32 levels deep");
  // Quotes, comments and CDATA do not hide levels from the check, and self-closing
  // elements do not count.
  std::string ok = "<ccomm version=\"1\"><node name=\"a\" interface=\"eth0\"/>";
  for (int i = 0; i < 100; ++i) ok += "<signal name=\"s" + std::to_string(i) + "\" type=\"bool\" producer=\"a\"/><!-- <x> -->";
  MustParse(ok + "</ccomm>");
  std::string hidden = "<ccomm version=\"1\">";
  for (int i = 0; i < 40; ++i) hidden += "<a b='>'><!-- <c> -->";
  err = MustFail(hidden);
  EXPECT_NE(err.find("nested more than 32"), std::string::npos) << err;
}

TEST(Load, UnreadableFiles) {
  SystemConfig cfg;
  std::string err;
  EXPECT_FALSE(LoadConfig(kSourceDir + "/no/such/file.xml", &cfg, &err));
  EXPECT_NE(err.find("file.xml: error: cannot open: No such file or directory"), std::string::npos)
      << err;
  EXPECT_FALSE(LoadConfig(kSourceDir + "/examples", &cfg, &err));
  EXPECT_NE(err.find("examples: error: not a regular file"), std::string::npos) << err;
}

// Every error line is "PATH:LINE: error: ..." with LINE inside the file, or "PATH: error:".
void CheckErrorFormat(const std::string& err, const std::string& path, size_t file_lines) {
  ASSERT_FALSE(err.empty());
  for (const std::string& line : Lines(err)) {
    ASSERT_EQ(line.rfind(path, 0), 0u) << line;
    std::string rest = line.substr(path.size());
    if (rest.rfind(": error: ", 0) == 0) continue;
    ASSERT_EQ(rest[0], ':') << line;
    size_t end = rest.find(": error: ");
    ASSERT_NE(end, std::string::npos) << line;
    int n = std::stoi(rest.substr(1, end - 1));
    EXPECT_GE(n, 1) << line;
    EXPECT_LE(static_cast<size_t>(n), file_lines) << line;
    EXPECT_GT(rest.size(), end + 9) << "empty message: " << line;
  }
}

// Random edits of valid files: the parser must never crash (ASan/UBSan builds check
// memory), must report well-formed messages, and must be deterministic.
TEST(Parse, SurvivesMutatedInput) {
  std::vector<std::string> files = XmlFilesIn(kSourceDir + "/examples");
  files.push_back(kSourceDir + "/dist/signals.xml");
  uint64_t rng = 0x9E3779B97F4A7C15ull;
  auto next = [&rng]() {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
  };
  const char kChars[] = "<>\"'=/&;#-, \n\t0123456789xabz.:!?[]";
  int accepted = 0, rejected = 0;
  for (const std::string& f : files) {
    const std::string original = ReadFile(f);
    ASSERT_FALSE(original.empty()) << f;
    for (int iter = 0; iter < 300; ++iter) {
      std::string t = original;
      const int edits = 1 + static_cast<int>(next() % 4);
      for (int k = 0; k < edits && !t.empty(); ++k) {
        size_t pos = next() % t.size();
        switch (next() % 5) {
          case 0: t[pos] = kChars[next() % (sizeof kChars - 1)]; break;
          case 1: t.erase(pos, 1 + next() % 16); break;
          case 2: t.insert(pos, t.substr(next() % t.size(), 1 + next() % 40)); break;
          case 3: t.resize(pos); break;
          case 4: t.insert(pos, 1, static_cast<char>(next() & 0xff)); break;
        }
      }
      SystemConfig cfg;
      std::string err, err2;
      bool ok = ParseConfig(t, "m.xml", &cfg, &err);
      SystemConfig cfg2;
      ASSERT_EQ(ParseConfig(t, "m.xml", &cfg2, &err2), ok);
      ASSERT_EQ(err, err2);
      if (ok) {
        ++accepted;
        EXPECT_TRUE(err.empty());
        EXPECT_EQ(cfg.hash, cfg2.hash);
      } else {
        ++rejected;
        const size_t lines = static_cast<size_t>(std::count(t.begin(), t.end(), '\n')) + 1;
        CheckErrorFormat(err, "m.xml", lines);
        if (HasFatalFailure()) {
          ADD_FAILURE() << "input was:\n" << t;
          return;
        }
      }
    }
  }
  // Both outcomes occur, or the mutations are not exercising anything.
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

// ---------------------------------------------------------- testdata/bad/*.xml
//
// Every file states the errors it must produce, one comment per error:
//   <!-- expect: LINE: MESSAGE FRAGMENT -->
// The parser must report exactly that many errors, each on its line and containing its
// fragment. Adding a file adds a case.

std::vector<std::string> BadFiles() { return XmlFilesIn(kSourceDir + "/src/config/testdata/bad"); }

class BadConfig : public ::testing::TestWithParam<std::string> {};

TEST_P(BadConfig, ReportsTheExpectedErrors) {
  const std::string& path = GetParam();
  const std::string text = ReadFile(path);
  struct Expect {
    int line;
    std::string fragment;
  };
  std::vector<Expect> expects;
  static const std::regex re("<!-- expect: ([0-9]+): (.*?) -->");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it)
    expects.push_back({std::stoi((*it)[1]), (*it)[2]});
  ASSERT_FALSE(expects.empty()) << path << " has no <!-- expect: LINE: MESSAGE --> comment";

  SystemConfig cfg;
  std::string err;
  ASSERT_FALSE(LoadConfig(path, &cfg, &err)) << path << " was accepted";
  CheckErrorFormat(err, path, static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1);
  std::vector<std::string> lines = Lines(err);
  EXPECT_EQ(lines.size(), expects.size()) << err;
  std::vector<bool> used(lines.size(), false);
  for (const Expect& e : expects) {
    const std::string prefix = path + ":" + std::to_string(e.line) + ": error: ";
    bool found = false;
    for (size_t i = 0; i < lines.size() && !found; ++i) {
      if (!used[i] && lines[i].rfind(prefix, 0) == 0 &&
          lines[i].find(e.fragment, prefix.size()) != std::string::npos) {
        used[i] = found = true;
      }
    }
    EXPECT_TRUE(found) << "missing: " << prefix << "..." << e.fragment << "\ngot:\n" << err;
  }
}

std::string CaseName(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = fs::path(info.param).stem().string();
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

INSTANTIATE_TEST_SUITE_P(Files, BadConfig, ::testing::ValuesIn(BadFiles()), CaseName);

TEST(BadConfigFiles, AtLeastTwenty) { EXPECT_GE(BadFiles().size(), 20u); }


// ------------------------------------------------------------- fan-out, monitors

TEST(Fanout, MonitorAndMulticastAreHashedAsDocumented) {
  // docs/config.md: the monitor is expanded into the consumer lists; fanout="multicast"
  // adds one line. Computed independently (Python) from that canonical form:
  //   ccomm-config 1\nnetwork 34997 47800\nfanout multicast 239.255.67.0\n
  //   node client\nnode server\nnode logger\nnode spare\n
  //   signal value double 1 state client server,logger,spare\n
  //   signal cmd int32 4 event server client,spare\n
  const std::string x = Replace(Replace(kHashBase, "udp_port=\"47800\"/>", "udp_port=\"47800\" fanout=\"multicast\"/>"),
                                "<node name=\"spare\" interface=\"eth0\"/>",
                                "<node name=\"spare\" interface=\"eth0\" monitor=\"*\"/>");
  SystemConfig cfg = MustParse(x);
  EXPECT_EQ(cfg.network.fanout, Fanout::kMulticast);
  EXPECT_EQ(cfg.signals[0].consumers, (std::vector<uint32_t>{1, 2, 3}));
  EXPECT_EQ(cfg.signals[1].consumers, (std::vector<uint32_t>{0, 3}));
  EXPECT_EQ(cfg.hash, 0xbbe8f4cau);
  // The default (unicast, no monitor) keeps the hash every existing file has.
  EXPECT_EQ(HashOf(Replace(kHashBase, "udp_port=\"47800\"/>", "udp_port=\"47800\" fanout=\"unicast\"/>")), 0x35465836u);
}

TEST(Fanout, MonitorPatternsSelectSignalsAndNeverTheirOwn) {
  SystemConfig cfg = MustParse(TwoNodes(
      "<node name=\"mon\" interface=\"eth0\" monitor=\"arm_*, cam_?\"/>\n"
      "<signal name=\"arm_q\" type=\"double\" producer=\"a\"/>\n"
      "<signal name=\"cam_1\" type=\"double\" producer=\"b\" consumers=\"mon\"/>\n"
      "<signal name=\"cam_10\" type=\"double\" producer=\"a\"/>\n"
      "<signal name=\"arm_mon\" type=\"double\" producer=\"mon\" consumers=\"a\"/>\n"));
  ASSERT_EQ(cfg.nodes[2].monitor, (std::vector<std::string>{"arm_*", "cam_?"}));
  EXPECT_EQ(cfg.signals[0].consumers, (std::vector<uint32_t>{2}));     // matched
  EXPECT_EQ(cfg.signals[1].consumers, (std::vector<uint32_t>{2}));     // listed once, not twice
  EXPECT_TRUE(cfg.signals[2].consumers.empty());                      // cam_? is one character
  EXPECT_EQ(cfg.signals[3].consumers, (std::vector<uint32_t>{0}));     // its own: not consumed
}

TEST(Fanout, BadValuesSayWhatIsExpected) {
  EXPECT_NE(MustFail(TwoNodes("<network fanout=\"broadcast\"/>")).find("unknown fanout 'broadcast' (expected unicast or multicast)"),
            std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<network multicast_base=\"10.0.0.0\"/>")).find("is not in 224.0.0.0/4"), std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<network multicast_base=\"239.1.1.250\"/>")).find("must leave room"), std::string::npos);
  EXPECT_NE(MustFail(TwoNodes("<node name=\"m\" interface=\"eth0\" monitor=\"a,,b\"/>")).find("empty pattern in monitor"),
            std::string::npos);
}

}  // namespace
}  // namespace ccomm

// SPDX-License-Identifier: Apache-2.0
// Tests of refused configurations: FILE:LINE errors, limits, mutated input, testdata/bad/.
#include "config/config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "config/config_test_util.h"

namespace ccomm {
namespace {

namespace fs = std::filesystem;

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

// One row of an edge-case table: XML either parses (error == nullptr) or is refused with a
// message that contains `error` and starts with "t.xml:LINE: error: ".
void ExpectParseOutcome(const std::string& xml, int line, const char* error, const std::string& label) {
  SystemConfig cfg;
  std::string err;
  bool ok = ParseConfig(xml, "t.xml", &cfg, &err);
  if (error == nullptr) {
    EXPECT_TRUE(ok) << label << ": " << err;
  } else {
    EXPECT_FALSE(ok) << label;
    EXPECT_NE(err.find(error), std::string::npos) << label << ": got " << err;
    EXPECT_EQ(err.rfind("t.xml:" + std::to_string(line) + ": error: ", 0), 0u) << err;
  }
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
      {R"(type="bool" stale_after_ms="5" stale_by="production")", nullptr},
      {R"(type="bool" stale_by="arrival")", nullptr},
      {R"(type="bool" stale_by="Production")", "unknown stale_by 'Production' (expected arrival or production)"},
      {R"(type="bool" stale_by="")", "unknown stale_by '' (expected arrival or production)"},
      {R"(type="bool" kind="event" stale_by="production")", "stale_by applies only to state signals"},
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
    ExpectParseOutcome(xml, 4, c.error, c.signal_attrs);
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
    ExpectParseOutcome(xml, 2, c.error, c.xml_fragment);
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

}  // namespace
}  // namespace ccomm

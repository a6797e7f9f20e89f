// What the configuration accepts as transport addresses (issue 22, items 4 and 9): LCM URLs parsed
// once and canonically (every spelling LCM would read as another port is refused, and two
// segments on one port are found whatever the spelling), and interface names that cannot carry
// quotes or control characters into logs or generated code.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "cosmic/config_loader.hpp"
#include "cosmic/lcm_url.hpp"
#include "cosmic/transport_limits.hpp"

namespace cosmic {
namespace {

std::string names_errors_text(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += e.to_string() + "\n";
  return out;
}

TEST(LcmUrl, CanonicalSpellingsAreRead) {
  const auto url = parse_lcm_url("udpm://239.255.76.67:7671?ttl=0&recv_buf_size=2097152");
  ASSERT_TRUE(url.ok()) << url.error().text;
  const LcmUrl& lcm = url.value();
  EXPECT_EQ(lcm.group, "239.255.76.67");
  EXPECT_EQ(lcm.port, 7671);
  EXPECT_EQ(lcm.ttl, 0u);
  EXPECT_EQ(lcm.recv_buf_size, 2097152u);
  EXPECT_EQ(parse_lcm_url("udpm://239.255.76.67").value().port, kLcmDefaultPort);
  EXPECT_EQ(parse_lcm_url("udpm://").value().group, "239.255.76.67");
  EXPECT_TRUE(parse_lcm_url("memq://").value().memq);
}

TEST(LcmUrl, EverySpellingLcmWouldReadAsAnotherPortIsRefused) {
  for (const char* bad :
       {"udpm://239.255.76.67:7667/", "udpm://239.255.76.67:7667 ", "udpm://239.255.76.67:0x1df3",
        "udpm://239.255.76.67:+7667", "udpm://239.255.76.67:07667x", "udpm://239.255.76.67:0",
        "udpm://239.255.76.67:65536", "udpm://239.255.76.67:", "udpm://10.0.0.1:7667", "udpm://239.255.076.67:7667",
        "udpm://239.255.76:7667", "udpm://239.255.76.67:7667?ttl=256", "udpm://239.255.76.67:7667?ttl=0x1",
        "udpm://239.255.76.67:7667?evil=1", "udpm://239.255.76.67:7667?ttl=0&", "udp://239.255.76.67:7667", "memq://x",
        "udpm://239.255.76.67:7667\"\n"}) {
    const auto url = parse_lcm_url(bad);
    ASSERT_FALSE(url.ok()) << bad << " was accepted";
    EXPECT_EQ(url.error().text.find('\n'), std::string::npos) << url.error().text;
  }
}

constexpr const char* kHead = "gateway: {name: gw, can_node_id: 1}\nsegments:\n";

TEST(LcmUrl, TwoSegmentsOnOnePortAreFoundWhateverTheSpellingAndBadUrlsAreLocated) {
  const ConfigResult r =
      parse_config(std::string(kHead) + R"(  - {name: a, type: lcm, url: "udpm://239.255.76.67:7667?ttl=0"}
  - {name: b, type: lcm, url: "udpm://239.255.76.68?ttl=1"}
  - {name: c, type: lcm, url: "udpm://239.255.76.67:7667/"}
channels: []
)",
                   "gw.yaml");
  const std::string text = names_errors_text(r.errors);
  EXPECT_NE(text.find("segments[1].url"), std::string::npos) << text;  // default port 7667 = a's port
  EXPECT_NE(text.find("UDP port 7667"), std::string::npos) << text;
  EXPECT_NE(text.find("gw.yaml:5:31: segments[2].url: unsupported LCM URL 'udpm://239.255.76.67:7667/': the port must "
                      "be a decimal"),
            std::string::npos)
      << text;
}

TEST(InterfaceNames, QuotesAndControlCharactersAreRefusedWhereTheyAreWritten) {
  EXPECT_TRUE(check_interface_name("can0").ok());
  EXPECT_TRUE(check_interface_name("eth0.100").ok());
  EXPECT_TRUE(check_interface_name("br-lan").ok());
  EXPECT_FALSE(check_interface_name("").ok());
  EXPECT_FALSE(check_interface_name("..").ok());
  EXPECT_FALSE(check_interface_name("can0/x").ok());
  EXPECT_FALSE(check_interface_name("sixteen_chars_xx").ok());
  const ConfigResult r =
      parse_config(std::string(kHead) + R"(  - {name: bus, type: can, interface: "vcan0\"\nint x;", bitrate: 500kbit/s}
  - {name: lan, type: dds, interfaces: [eth0, "lo\"x"]}
channels: []
)",
                   "gw.yaml");
  const std::string text = names_errors_text(r.errors);
  EXPECT_NE(text.find("gw.yaml:3:39: segments[0].interface: interface names hold letters, digits, '_', '.', '@' and "
                      "'-' only; this one has '\"'"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("segments[1].interfaces[1]: invalid name"), std::string::npos) << text;
  EXPECT_EQ(text.find("int x;"), std::string::npos)
      << "the value itself is never echoed with its control characters: " << text;
}

TEST(LcmChannelNames, ANulOrControlCharacterIsRefusedBeforeItReachesTheWire) {
  EXPECT_TRUE(check_transport_name(SegmentType::lcm, "WHEEL_SPEED").ok());
  EXPECT_TRUE(check_transport_name(SegmentType::lcm, "odometry/pose 2").ok());  // LCM allows these
  EXPECT_FALSE(check_transport_name(SegmentType::lcm, std::string("A\0B", 3)).ok());
  EXPECT_FALSE(check_transport_name(SegmentType::lcm, "A\nB").ok());
  EXPECT_FALSE(check_transport_name(SegmentType::lcm, "A\x7f").ok());
  EXPECT_TRUE(check_transport_name(SegmentType::dds, std::string("A\0B", 3)).ok());  // DDS names are checked elsewhere
  // In a native binding of the configuration, at its place.
  const ConfigResult r = parse_config(std::string(kHead) + R"(  - {name: lan, type: dds}
  - {name: viz, type: lcm}
channels:
  - {name: wheel, subject: 1, class: nrt, publishers: [lan], subscribers: [viz], native: {viz: {channel: "WHEEL\u0000SPEED"}}}
)",
                                      "gw.yaml");
  const std::string text = names_errors_text(r.errors);
  EXPECT_NE(text.find("gw.yaml:6:"), std::string::npos) << text;
  EXPECT_NE(text.find("LCM channel names hold no control characters; this one has 0x00"), std::string::npos) << text;
}

}  // namespace
}  // namespace cosmic

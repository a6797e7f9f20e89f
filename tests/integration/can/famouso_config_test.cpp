// The per-segment `profile` key of CAN segments (docs/yaml-reference.md): default, famouso, and
// the located errors for a wrong value and for FAMOUSO on CAN FD.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

std::string config_with(const std::string& segment_extra) {
  return "gateway:\n  name: gw\nsegments:\n  - name: bus\n    type: can\n    interface: vcan0\n"
         "    bitrate: 500kbit/s\n" +
         segment_extra + "channels: []\n";
}

TEST(CanProfileConfig, DefaultIsCosmicAndFamousoIsAccepted) {
  const ConfigResult plain = parse_config(config_with(""), "gw.yaml");
  ASSERT_TRUE(plain.ok()) << plain.errors.front().to_string();
  EXPECT_EQ(plain.config.segments.at(0).can.profile, CanProfile::cosmic);
  const ConfigResult famouso = parse_config(config_with("    profile: famouso\n"), "gw.yaml");
  ASSERT_TRUE(famouso.ok()) << famouso.errors.front().to_string();
  EXPECT_EQ(famouso.config.segments.at(0).can.profile, CanProfile::famouso);
}

TEST(CanProfileConfig, WrongValueAndFdAreLocatedErrors) {
  const ConfigResult wrong = parse_config(config_with("    profile: canopen\n"), "gw.yaml");
  ASSERT_EQ(wrong.errors.size(), 1u);
  EXPECT_EQ(wrong.errors[0].path, "segments[0].profile");
  EXPECT_EQ(wrong.errors[0].line, 8);
  EXPECT_NE(wrong.errors[0].valid.find("famouso"), std::string::npos);
  const ConfigResult fd = parse_config(config_with("    fd: true\n    profile: famouso\n"), "gw.yaml");
  ASSERT_EQ(fd.errors.size(), 1u);
  EXPECT_EQ(fd.errors[0].path, "segments[0].profile");
  EXPECT_NE(fd.errors[0].message.find("classic CAN"), std::string::npos);
}

}  // namespace
}  // namespace cosmic

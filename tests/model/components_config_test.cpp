// The `components:` section: P/S segments derived from components, agreement with explicit lists,
// located errors, and files without components unchanged.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/knowledge_base.hpp"

namespace {

constexpr const char* kSegments = R"(
segments:
  - {name: bus, type: can, interface: vcan0, bitrate: 500kbit/s}
  - {name: lan, type: dds, domain: 0}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7667?ttl=0"}
)";

cosmic::ConfigResult parse(const std::string& rest) {
  return cosmic::parse_config(std::string(kSegments) + rest, "t.yaml");
}

std::string errors(const cosmic::ConfigResult& r) {
  std::string out;
  for (const auto& e : r.errors) out += e.to_string() + "\n";
  return out;
}

TEST(Components, DeriveBindingsInSegmentOrder) {
  const auto r = parse(R"(channels:
  - {name: speed, subject: 1, class: nrt, max_rate: 10Hz}
components:
  - {name: viewer, segment: viz, subscribes: [speed]}
  - {name: controller, segment: lan, publishes: [speed]}
  - {name: drive, segment: bus, subscribes: [speed]}
  - {name: local, segment: lan, subscribes: [speed]}
)");
  ASSERT_TRUE(r.ok()) << errors(r);
  const auto* speed = r.config.find_channel("speed");
  EXPECT_EQ(speed->publishers, (std::vector<std::string>{"lan"}));
  // segment order, and the subscriber on the publisher segment adds no S tag
  EXPECT_EQ(speed->subscribers, (std::vector<std::string>{"bus", "viz"}));
  ASSERT_EQ(r.config.components.size(), 4u);
  EXPECT_EQ(r.config.components[1].segment, "lan");
}

TEST(Components, WithoutComponentsListsStayRequired) {
  const auto r = parse("channels:\n  - {name: a, subject: 1, class: nrt}\n");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(errors(r).find("channels[0].publishers: missing required key 'publishers'"), std::string::npos)
      << errors(r);
}

TEST(Components, ExplicitListsMustAgree) {
  const auto r = parse(R"(channels:
  - {name: a, subject: 1, class: nrt, publishers: [bus], subscribers: [lan]}
components:
  - {name: c, segment: viz, publishes: [a], subscribes: [a]}
)");
  ASSERT_EQ(r.errors.size(), 2u) << errors(r);
  EXPECT_EQ(r.errors[0].to_string(),
            "t.yaml:9:41: components[0].publishes[0]: component 'c' on segment 'viz' publishes 'a', which the "
            "gateway does not bind there (a component on a segment listed in its publishers (bus))");
  EXPECT_NE(r.errors[1].message.find("subscribes 'a'"), std::string::npos);
}

TEST(Components, EveryProblemLocatedAtOnce) {
  const auto r = parse(R"(channels:
  - {name: a, subject: 1, class: nrt}
  - {name: b, subject: 2, class: nrt, publishers: [bus], subscribers: [lan]}
components:
  - {name: x, segment: nowhere, publishes: [a]}
  - {name: v, segment: lan, publishes: [ghost, b, b]}
  - {name: y, segment: bus, publishes: [b]}
  - {name: y, segment: lan, subscribes: [b]}
  - {name: z, segment: lan}
  - {name: w, segment: lan, publishes: [b], colour: red}
)");
  const std::string e = errors(r);
  EXPECT_NE(
      e.find("t.yaml:10:24: components[0].segment: unknown segment 'nowhere' (one of the segments: bus, lan, viz)"),
      std::string::npos)
      << e;
  EXPECT_NE(e.find("components[1].publishes[0]: unknown channel 'ghost' (one of the channels: a, b)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("components[1].publishes[2]: channel 'b' listed twice"), std::string::npos) << e;
  EXPECT_NE(
      e.find(
          "components[3].name: duplicate component name 'y' (a name not used by another component (first at line 12))"),
      std::string::npos)
      << e;
  EXPECT_NE(e.find("components[4]: component neither publishes nor subscribes"), std::string::npos) << e;
  EXPECT_NE(e.find("components[5].colour: unknown key 'colour'"), std::string::npos) << e;
  // a: nobody valid publishes or subscribes it
  EXPECT_NE(e.find("channels[0].publishers: no publishers given and none derived from components"), std::string::npos)
      << e;
  EXPECT_NE(e.find("channels[0].subscribers: no subscribers given"), std::string::npos) << e;
}

TEST(Components, RobotDerivesTodaysBindings) {
  const auto r = cosmic::load_config_file(std::string(cosmic::build_paths::source_dir) + "/config/robot.yaml");
  ASSERT_TRUE(r.ok()) << errors(r);
  using L = std::vector<std::string>;
  const std::map<std::string, std::pair<L, L>> expected{{"distance", {{"body-can"}, {"lan"}}},
                                                        {"acceleration", {{"body-can"}, {"lan"}}},
                                                        {"odometry", {{"body-can"}, {"lan"}}},
                                                        {"obstacle", {{"lan"}, {"body-can"}}},
                                                        {"speed", {{"lan"}, {"body-can", "viz"}}},
                                                        {"command", {{"lan"}, {"body-can"}}},
                                                        {"actual_speed", {{"body-can"}, {"lan", "viz"}}},
                                                        {"diagnostics", {{"body-can"}, {"viz"}}}};
  ASSERT_EQ(r.config.channels.size(), expected.size());
  for (const auto& c : r.config.channels) {
    EXPECT_EQ(c.publishers, expected.at(c.name).first) << c.name;
    EXPECT_EQ(c.subscribers, expected.at(c.name).second) << c.name;
  }
  const auto report = cosmic::admit_all(r.config);
  for (const auto& c : report.channels) EXPECT_EQ(c.verdict, cosmic::Verdict::bound) << c.name;
}

}  // namespace

// Native DDS channels (issue 19, item 4): a channel that is a DDS topic of any type, carried as its
// serialized sample. The YAML key and its located errors, the naming rules every layer shares
// (cosmic/dds_names.hpp), the encapsulation header a writer checks, the knowledge base's identity
// rule and the report's DDS hop.
#include <gtest/gtest.h>

#include <array>

#include "cosmic/admission.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/dds_encapsulation.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace cosmic::test;

std::string native_errors_text(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += e.to_string() + "\n";
  return out;
}

constexpr const char* kNativeSegments = R"(gateway: {name: gw, can_node_id: 1}
segments:
  - {name: lan, type: dds, domain: 3, latency_bound: 1ms, realtime: true}
  - {name: robot, type: dds, domain: 4, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
)";

ConfigResult parse_native(const std::string& channels) {
  return parse_config(std::string(kNativeSegments) + channels, "gw.yaml");
}

constexpr const char* kTwist = "geometry_msgs::msg::dds_::Twist_";

TEST(NativeDdsConfig, TopicTypeAndRepresentationAreReadAndPersisted) {
  const ConfigResult r = parse_native(
      R"(  - {name: cmd_vel, subject: 0x20, class: srt, period: 10ms, reaction_time: 50ms, payload: 52B, publishers: [robot], subscribers: [lan, viz],
     native: {robot: {topic: rt/cmd_vel, type: "geometry_msgs::msg::dds_::Twist_"}, lan: {topic: rt/ns1/cmd_vel, type: "geometry_msgs::msg::dds_::Twist_", representation: xcdr2, keyed: false}}}
)");
  ASSERT_TRUE(r.ok()) << native_errors_text(r.errors);
  const ChannelSpec& c = r.config.channels.at(0);
  EXPECT_EQ(c.native_dds("robot"), (NativeDdsTopic{"rt/cmd_vel", kTwist, DdsRepresentation::xcdr1}));
  EXPECT_EQ(c.native_dds("lan"), (NativeDdsTopic{"rt/ns1/cmd_vel", kTwist, DdsRepresentation::xcdr2}));
  EXPECT_FALSE(c.native_dds("viz"));
  const ChannelsResult back = parse_channels(channel_to_yaml(c), "state", r.config);
  ASSERT_TRUE(back.errors.empty()) << native_errors_text(back.errors) << channel_to_yaml(c);
  EXPECT_EQ(back.channels.at(0), c) << channel_to_yaml(c);
}

TEST(NativeDdsConfig, EveryProblemIsLocatedAtOnce) {
  const ConfigResult r = parse_native(
      R"(  - {name: a, subject: 0x10, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: "rt/cmd vel", type: T}}}
  - {name: b, subject: 0x11, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: cosmic/b, type: T}}}
  - {name: c, subject: 0x12, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: rt/c, type: "pkg::::T"}}}
  - {name: d, subject: 0x13, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: rt/d, type: "cosmic::Envelope"}}}
  - {name: e, subject: 0x14, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: rt/e, type: T, keyed: true}}}
  - {name: f, subject: 0x15, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: rt/f, type: T, representation: xml}}}
  - {name: g, subject: 0x16, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {type: T}}}
  - {name: h, subject: 0x17, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: rt/h, type: T}}}
  - {name: i, subject: 0x18, class: nrt, payload: 52B, publishers: [lan], subscribers: [robot], native: {robot: {topic: rt/h, type: T}}}
  - {name: j, subject: 0x19, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: "rt//j", type: T}}}
  - {name: k, subject: 0x1A, class: nrt, payload: 52B, publishers: [robot], subscribers: [lan], native: {robot: {topic: "rt/k\"\n", type: T}}}
)");
  const std::string text = native_errors_text(r.errors);
  EXPECT_NE(text.find("gw.yaml:7:121: channels[0].native.robot.topic: topic name 'rt/cmd vel' has 0x20 at position 7"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[1].native.robot.topic: topic name 'cosmic/b' is under cosmic/"), std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[2].native.robot.type: type name 'pkg::::T' has a part that is not an IDL identifier"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[3].native.robot.type: cosmic::Envelope is the gateway's own envelope type"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[4].native.robot.keyed: keyed types are not carried"), std::string::npos) << text;
  EXPECT_NE(text.find("channels[5].native.robot.representation: unknown representation 'xml'"), std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[6].native.robot.topic: missing required key 'topic'"), std::string::npos) << text;
  EXPECT_NE(text.find("channels[8].native.robot: rt/h on segment robot is already channel h's (line 14)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[9].native.robot.topic: topic name 'rt//j' has an empty part between '/' separators"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[10].native.robot.topic: topic name 'rt/k\"\\x0A' has '\"' at position 5"),
            std::string::npos)
      << text;
  EXPECT_EQ(r.errors.size(), 10u) << text;
}

TEST(DdsNames, EnvelopeAndNativeTopicsAreNamedOneWayEverywhere) {
  ChannelSpec c = channel("robot.arm-left_2", 0x1, ChannelClass::srt, {"robot"}, {"lan"}, 52);
  EXPECT_EQ(dds_topic_of(c, "lan"),
            (DdsTopicRef{"cosmic/robot_arm_left_2", kEnvelopeTypeName, false, DdsRepresentation::xcdr1}));
  c.native.push_back(
      NativeBinding{"robot", std::nullopt, std::nullopt, NativeDdsTopic{"rt/arm", kTwist, DdsRepresentation::xcdr2}});
  EXPECT_EQ(dds_topic_of(c, "robot"), (DdsTopicRef{"rt/arm", kTwist, true, DdsRepresentation::xcdr2}));
  EXPECT_EQ(dds_topic_of(c, "lan").topic, "cosmic/robot_arm_left_2");
  // Two channels on one topic: named, whichever way they got there.
  const ChannelSpec a = channel("a-b", 0x2, ChannelClass::nrt, {"lan"}, {"robot"}, 8);
  const ChannelSpec b = channel("a.b", 0x3, ChannelClass::nrt, {"lan"}, {"robot"}, 8);
  const std::array<const ChannelSpec*, 2> envelope{&a, &b};
  EXPECT_EQ(check_dds_topics_distinct(envelope, "lan").error().text,
            "channels 'a-b' and 'a.b' both map to DDS topic cosmic/a_b ('-' and '.' become '_'); rename one of them");
  ChannelSpec d = channel("d", 0x4, ChannelClass::nrt, {"robot"}, {"lan"}, 8);
  d.native.push_back(
      NativeBinding{"robot", std::nullopt, std::nullopt, NativeDdsTopic{"rt/arm", kTwist, DdsRepresentation::xcdr1}});
  const std::array<const ChannelSpec*, 2> native{&c, &d};
  EXPECT_EQ(check_dds_topics_distinct(native, "robot").error().text,
            "channels 'robot.arm-left_2' and 'd' both map to DDS topic rt/arm; rename one of them");
  EXPECT_TRUE(check_dds_topics_distinct(native, "lan").ok());
  EXPECT_TRUE(check_dds_topic_name("rt/ns/cmd_vel").ok());
  EXPECT_FALSE(check_dds_topic_name("").ok());
  EXPECT_FALSE(check_dds_topic_name("/rt/x").ok());
  EXPECT_FALSE(check_dds_topic_name("rt/x/").ok());
  EXPECT_FALSE(check_dds_topic_name(std::string(kMaxDdsNameLength + 1, 'a')).ok());
  EXPECT_TRUE(check_dds_type_name("std_msgs::msg::dds_::String_").ok());
  EXPECT_TRUE(check_dds_type_name("_T").ok());
  EXPECT_FALSE(check_dds_type_name("::T").ok());
  EXPECT_FALSE(check_dds_type_name("T::").ok());
  EXPECT_FALSE(check_dds_type_name("1T").ok());
  EXPECT_FALSE(check_dds_type_name("a:b").ok());
}

TEST(DdsEncapsulation, NamesEveryCdrIdentifierAndRefusesTheRest) {
  struct Case {
    std::array<std::uint8_t, 4> header;
    DdsRepresentation representation;
    bool little_endian;
    const char* name;
  };
  const Case known[] = {
      {{0x00, 0x00, 0, 0}, DdsRepresentation::xcdr1, false, "CDR_BE"},
      {{0x00, 0x01, 0, 0}, DdsRepresentation::xcdr1, true, "CDR_LE"},
      {{0x00, 0x03, 0, 0}, DdsRepresentation::xcdr1, true, "PL_CDR_LE"},
      {{0x00, 0x06, 0, 0}, DdsRepresentation::xcdr2, false, "CDR2_BE"},
      {{0x00, 0x07, 0, 3}, DdsRepresentation::xcdr2, true, "CDR2_LE"},
      {{0x00, 0x09, 0, 0}, DdsRepresentation::xcdr2, true, "D_CDR2_LE"},
      {{0x00, 0x0b, 0, 0}, DdsRepresentation::xcdr2, true, "PL_CDR2_LE"},
  };
  for (const Case& c : known) {
    const auto header = read_dds_encapsulation(c.header);
    ASSERT_TRUE(header) << c.name;
    EXPECT_EQ(header->representation, c.representation) << c.name;
    EXPECT_EQ(header->little_endian, c.little_endian) << c.name;
    EXPECT_STREQ(header->name, c.name);
  }
  const std::array<std::uint8_t, 4> xml{0x00, 0x04, 0, 0};
  const std::array<std::uint8_t, 4> vendor{0x80, 0x01, 0, 0};
  const std::array<std::uint8_t, 4> swapped{0x01, 0x00, 0, 0};
  const std::array<std::uint8_t, 3> short_sample{0x00, 0x01, 0};
  EXPECT_FALSE(read_dds_encapsulation(xml));
  EXPECT_FALSE(read_dds_encapsulation(vendor));
  EXPECT_FALSE(read_dds_encapsulation(swapped));
  EXPECT_FALSE(read_dds_encapsulation(short_sample));
}

Config two_domains() {
  Config c;
  c.gateway.can_node_id = 1;
  c.segments = {dds_segment("lan"), dds_segment("robot")};
  return c;
}

ChannelSpec native_twist(const std::string& name, std::uint64_t subject, const std::string& topic) {
  ChannelSpec c = channel(name, subject, ChannelClass::srt, {"robot"}, {"lan"}, 52);
  c.native.push_back(
      NativeBinding{"robot", std::nullopt, std::nullopt, NativeDdsTopic{topic, kTwist, DdsRepresentation::xcdr1}});
  return c;
}

TEST(NativeDdsKnowledgeBase, ATopicHasOneChannelPerSegment) {
  const Config c = two_domains();
  KnowledgeBase kb(c.gateway, c.segments);
  ASSERT_TRUE(kb.bind(native_twist("cmd_vel", 0x20, "rt/cmd_vel")).bound());
  const BindOutcome taken = kb.bind(native_twist("cmd_vel2", 0x21, "rt/cmd_vel"));
  EXPECT_FALSE(taken.bound());
  ASSERT_FALSE(taken.report.reasons.empty());
  EXPECT_NE(taken.report.reasons.at(0).find("rt/cmd_vel"), std::string::npos) << taken.report.reasons.at(0);
  EXPECT_NE(taken.report.reasons.at(0).find("cmd_vel"), std::string::npos);
  EXPECT_TRUE(kb.unbind("cmd_vel"));
  EXPECT_TRUE(kb.bind(native_twist("cmd_vel2", 0x21, "rt/cmd_vel")).bound());
}

TEST(NativeDdsReport, EveryDdsHopShowsItsTopicAndType) {
  Config c = two_domains();
  c.channels = {native_twist("cmd_vel", 0x20, "rt/cmd_vel")};
  const AdmissionReport report = admit_all(c);
  const nlohmann::json hops = to_json(report)["channels"][0]["hops"];
  ASSERT_EQ(hops.size(), 2u);
  EXPECT_EQ(hops[0]["segment"], "robot");
  EXPECT_EQ(
      hops[0]["dds"],
      (nlohmann::json{{"topic", "rt/cmd_vel"}, {"type", kTwist}, {"layout", "native"}, {"representation", "xcdr1"}}));
  EXPECT_EQ(hops[1]["dds"],
            (nlohmann::json{{"topic", "cosmic/cmd_vel"}, {"type", "cosmic::Envelope"}, {"layout", "envelope"}}));
  const std::string text = render_channel_text(report.channels[0]);
  EXPECT_NE(text.find("publisher robot  topic rt/cmd_vel type geometry_msgs::msg::dds_::Twist_"), std::string::npos)
      << text;
  EXPECT_NE(text.find("subscriber lan  topic cosmic/cmd_vel type cosmic::Envelope"), std::string::npos) << text;
}

}  // namespace
}  // namespace cosmic

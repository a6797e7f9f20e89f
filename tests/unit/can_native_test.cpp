// Native CAN channels (issue 19, item 3): a channel that is one identifier the devices on the bus
// already use. The YAML key, its located errors, the knowledge base's identity and etag rules,
// admission (the identifier is the frame's priority; one frame per event) and the report.
#include <gtest/gtest.h>

#include "cosmic/admission.hpp"
#include "cosmic/can_interference.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;

std::string errors_text(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += e.to_string() + "\n";
  return out;
}

constexpr const char* kSegments = R"(gateway: {name: gw, can_node_id: 1, residence_bound: 500us}
segments:
  - name: body
    type: can
    interface: vcan0
    bitrate: 500kbit/s
    background: {frames: [{name: Engine, can_id: 0x0C0, dlc: 8, period: 10ms}, {name: J1939, can_id: 0x18EFFF01, extended: true, dlc: 8, period: 100ms}]}
  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
)";

ConfigResult parse(const std::string& channels) { return parse_config(std::string(kSegments) + channels, "gw.yaml"); }

TEST(NativeCanConfig, StandardExtendedAndLcmIdentitiesAreRead) {
  const ConfigResult r = parse(
      R"(  - {name: wheel, subject: 0x10, class: hrt, period: 10ms, reaction_time: 5ms, payload: 8B, publishers: [body], subscribers: [lan, viz],
     native: {body: {can_id: 0x123}, viz: {channel: WHEEL_SPEED}}}
  - {name: lamp, subject: 0x11, class: srt, period: 20ms, reaction_time: 20ms, payload: 2B, publishers: [lan], subscribers: [body],
     native: {body: {can_id: 0x18FF0123, extended: true}}}
)");
  ASSERT_TRUE(r.ok()) << errors_text(r.errors);
  const ChannelSpec& wheel = r.config.channels[0];
  ASSERT_EQ(wheel.native.size(), 2u);
  EXPECT_EQ(wheel.native_can("body"), (NativeCanFrame{0x123, false}));
  EXPECT_EQ(wheel.native_on("viz")->lcm_channel, "WHEEL_SPEED");
  EXPECT_FALSE(wheel.native_can("lan"));
  EXPECT_EQ(r.config.channels[1].native_can("body"), (NativeCanFrame{0x18FF0123, true}));
  // Persisted (cosmicctl bind) and read back unchanged.
  for (const ChannelSpec& c : r.config.channels) {
    const ChannelsResult back = parse_channels(channel_to_yaml(c), "state", r.config);
    ASSERT_TRUE(back.errors.empty()) << errors_text(back.errors) << channel_to_yaml(c);
    EXPECT_EQ(back.channels.at(0), c) << channel_to_yaml(c);
  }
}

TEST(NativeCanConfig, EveryProblemIsLocatedAtOnce) {
  const ConfigResult r = parse(
      R"(  - {name: a, subject: 0x10, class: srt, period: 10ms, reaction_time: 5ms, publishers: [body], subscribers: [lan],
     native: {body: {can_id: 0x800}}}
  - {name: b, subject: 0x11, class: srt, period: 10ms, reaction_time: 5ms, publishers: [body], subscribers: [lan],
     native: {body: {can_id: 0x18FF0002, extended: true}}}
  - {name: c, subject: 0x12, class: srt, period: 10ms, reaction_time: 5ms, publishers: [body], subscribers: [lan],
     native: {body: {can_id: 0x0C0}}}
  - {name: d, subject: 0x13, class: srt, period: 10ms, reaction_time: 5ms, publishers: [body], subscribers: [viz],
     native: {lan: {topic: rt/x}, nowhere: {can_id: 1}}}
  - {name: e, subject: 0x14, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [viz],
     native: {body: {can_id: 0x200}}}
  - {name: f, subject: 0x15, class: srt, period: 10ms, reaction_time: 5ms, publishers: [body], subscribers: [lan],
     native: {body: {can_id: 0x300}}}
  - {name: g, subject: 0x16, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [body],
     native: {body: {can_id: 0x300, extra: 1}}}
  - {name: h, subject: 0x17, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [body],
     native: {body: {can_id: 0x301}}}
  - {name: i, subject: 0x18, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [body],
     native: {body: {can_id: 0x301}}}
  - {name: j, subject: 0x19, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [viz], native: [body]}
)");
  const std::string text = errors_text(r.errors);
  EXPECT_NE(text.find("gw.yaml:12:30: channels[0].native.body.can_id: '0x800' is out of range"), std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[1].native.body.can_id: extended identifier 0x18FF0002 has etag bits 2, which the "
                      "binding protocols use"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[2].native.body.can_id: 0x0C0 is declared as background frame Engine (gw.yaml:7:"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[3].native.lan.type: missing required key 'type'"), std::string::npos) << text;
  EXPECT_NE(text.find("channels[3].native.nowhere: unknown segment 'nowhere'"), std::string::npos) << text;
  EXPECT_NE(text.find("channels[4].native.body: segment 'body' is neither a publisher nor a subscriber of channel e"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[6].native.body.extra: unknown key 'extra'"), std::string::npos) << text;
  EXPECT_NE(text.find("channels[8].native.body: 0x301 on segment body is already channel h's (line 26)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("channels[9].native: expected a map of segment names"), std::string::npos) << text;
  EXPECT_EQ(r.errors.size(), 9u) << text;
}

Config native_bus() {
  Config c;
  c.gateway.can_node_id = 1;
  c.gateway.residence_bound = 500us;
  c.segments = {can_segment("body", 500'000, 0.9), dds_segment("lan")};
  return c;
}

ChannelSpec native_channel(const std::string& name, std::uint64_t subject, ChannelClass cls, NativeCanFrame frame,
                           bool from_can = true, std::uint64_t payload = 8) {
  ChannelSpec c = from_can ? channel(name, subject, cls, {"body"}, {"lan"}, payload)
                           : channel(name, subject, cls, {"lan"}, {"body"}, payload);
  c.native.push_back(NativeBinding{"body", frame, std::nullopt, std::nullopt});
  return c;
}

const CanHopPlan& can_hop(const ChannelReport& report) {
  for (const HopReport& h : report.hops) {
    if (h.can) return *h.can;
  }
  throw std::runtime_error("no CAN hop");
}

TEST(NativeCanAdmission, TheIdentifierIsTheFramesPriorityAndOneFrameIsTheEvent) {
  Config c = native_bus();
  // speed goes out with an extended identifier whose 11 base bits are 0x080 (priority 0x10).
  c.channels = {channel("speed", 0x51, ChannelClass::srt, {"lan"}, {"body"}),
                native_channel("wheel", 0x10, ChannelClass::hrt, NativeCanFrame{0x010, false})};
  const Evaluation e = evaluate(c.gateway, c.segments, c.channels, {});
  const CanHopPlan& wheel = can_hop(e.channels[1]);
  EXPECT_TRUE(wheel.native);
  EXPECT_FALSE(wheel.extended);
  EXPECT_EQ(wheel.can_id, 0x010u);
  EXPECT_EQ(wheel.etag, 0u);
  EXPECT_EQ(wheel.frames_per_event, 1u);
  // A standard 8-byte frame is shorter than an extended one: 135 bits worst case at 500 kbit/s.
  EXPECT_EQ(wheel.transmission, frame_time(c.segments[0].can, 8, CanIdFormat::standard11));
  EXPECT_LT(wheel.transmission, can_hop(e.channels[0]).transmission);
  // The native frame beats speed (0x010 < 0x080): speed's response time holds one more frame.
  Config alone = c;
  alone.channels.pop_back();
  const Evaluation without = evaluate(alone.gateway, alone.segments, alone.channels, {});
  EXPECT_EQ(*can_hop(e.channels[0]).response_time, *can_hop(without.channels[0]).response_time + wheel.transmission);
}

// A native channel delays the gateway's other frames exactly as a background frame of the same
// identifier, length and period does: the analysis knows no difference.
TEST(NativeCanAdmission, ANativeChannelWeighsLikeTheSameBackgroundFrame) {
  for (const NativeCanFrame& frame :
       {NativeCanFrame{0x020, false}, NativeCanFrame{0x600, false}, NativeCanFrame{0x00FF1234, true}}) {
    Config with_native = native_bus();
    with_native.channels = {channel("speed", 0x51, ChannelClass::srt, {"lan"}, {"body"}),
                            native_channel("wheel", 0x10, ChannelClass::srt, frame, true, 8)};
    Config with_background = native_bus();
    with_background.channels = {with_native.channels[0]};
    with_background.segments[0].can.background.push_back(
        CanBackgroundFrame{"wheel", frame.can_id, frame.extended, 8, Nanos(10ms), Nanos(0), "test", std::nullopt});
    const Evaluation a = evaluate(with_native.gateway, with_native.segments, with_native.channels, {});
    const Evaluation b = evaluate(with_background.gateway, with_background.segments, with_background.channels, {});
    EXPECT_EQ(can_hop(a.channels[0]).response_time, can_hop(b.channels[0]).response_time) << std::hex << frame.can_id;
    EXPECT_DOUBLE_EQ(a.segments[0].utilization, b.segments[0].utilization) << std::hex << frame.can_id;
  }
}

TEST(NativeCanAdmission, APayloadThatDoesNotFitOneFrameIsRefusedWhateverTheClass) {
  Config c = native_bus();
  c.channels = {native_channel("bulk", 0x10, ChannelClass::nrt, NativeCanFrame{0x123, false}, true, 9)};
  const AdmissionReport report = admit_all(c);
  ASSERT_EQ(report.channels.size(), 1u);
  EXPECT_EQ(report.channels[0].verdict, Verdict::rejected);
  ASSERT_FALSE(report.channels[0].reasons.empty());
  EXPECT_NE(report.channels[0].reasons[0].find("payload 9 B > native frame 8 B on body"), std::string::npos)
      << report.channels[0].reasons[0];
  // CAN FD carries up to 64 bytes in one frame.
  c.segments[0].can.fd = true;
  c.segments[0].can.data_bitrate = BitRate{2'000'000};
  c.channels[0].payload = 64;
  EXPECT_NE(admit_all(c).channels[0].verdict, Verdict::rejected);
}

TEST(NativeCanKnowledgeBase, IdentitiesAndEtagBitsAreNeverShared) {
  Config c = native_bus();
  c.segments[0].can.background.push_back(
      CanBackgroundFrame{"J1939", 0x18EFFF01, true, 8, Nanos(100ms), Nanos(0), "test", std::nullopt});
  KnowledgeBase kb(c.gateway, c.segments, {});
  ASSERT_TRUE(kb.bind(native_channel("wheel", 0x10, ChannelClass::srt, NativeCanFrame{0x00FF3FFF, true})).bound());
  // A dynamic etag skips 16383 (the native identifier's etag bits) and the background frame's 16129.
  ASSERT_TRUE(kb.bind(channel("speed", 0x51, ChannelClass::srt, {"lan"}, {"body"})).bound());
  EXPECT_EQ(kb.etag_of("speed"), 16382);
  ChannelSpec second = channel("other", 0x52, ChannelClass::srt, {"lan"}, {"body"});
  for (int i = 0; i < 254; ++i) {
    second.name = "other" + std::to_string(i);
    second.subject = 0x100 + static_cast<std::uint64_t>(i);
    second.reaction_time = 1s;
    second.period = 1s;
    second.cls = ChannelClass::nrt;
    ASSERT_TRUE(kb.bind(second).bound()) << i;
    ASSERT_NE(kb.etag_of(second.name), 16129) << i;
  }
  // The same identifier again, on the same bus: refused with the owner named.
  const BindOutcome again =
      kb.bind(native_channel("wheel2", 0x11, ChannelClass::srt, NativeCanFrame{0x00FF3FFF, true}, false));
  EXPECT_FALSE(again.bound());
  EXPECT_EQ(again.report.reasons.at(0), "0x00FF3FFF on segment body is already carried by bound channel wheel");
  // An extended identifier whose etag bits a bound COSMIC channel uses, and the reverse.
  const BindOutcome clash =
      kb.bind(native_channel("lamp", 0x12, ChannelClass::srt, NativeCanFrame{0x00AA0000 | 16382, true}));
  EXPECT_FALSE(clash.bound());
  EXPECT_EQ(clash.report.reasons.at(0),
            "extended identifier 0x00AA3FFE reads as etag 16382 of bound channel speed to COSMIC devices");
  ChannelSpec fixed = channel("fixed", 0x53, ChannelClass::srt, {"lan"}, {"body"});
  fixed.etag = 16383;
  const BindOutcome taken = kb.bind(fixed);
  EXPECT_FALSE(taken.bound());
  EXPECT_EQ(taken.report.reasons.at(0),
            "etag 16383 is the etag bits of bound channel wheel's native extended identifier");
  // Unbound, the identifier is free again.
  EXPECT_TRUE(kb.unbind("wheel"));
  EXPECT_TRUE(
      kb.bind(native_channel("wheel2", 0x11, ChannelClass::srt, NativeCanFrame{0x00FF3FFF, true}, false)).bound());
}

TEST(NativeCanReport, TheHopShowsTheNativeIdentifier) {
  Config c = native_bus();
  c.channels = {native_channel("wheel", 0x10, ChannelClass::hrt, NativeCanFrame{0x123, false})};
  const AdmissionReport report = admit_all(c);
  const nlohmann::json hop = to_json(report)["channels"][0]["hops"][0]["can"];
  EXPECT_EQ(hop["layout"], "native");
  EXPECT_EQ(hop["can_id"], 0x123);
  EXPECT_EQ(hop["extended"], false);
  EXPECT_FALSE(hop.contains("etag"));
  EXPECT_EQ(hop["frames_per_event"], 1);
  const std::string text = render_channel_text(report.channels[0]);
  EXPECT_NE(text.find("id 0x123 (native, standard)"), std::string::npos) << text;
}

// Item 2: a frame seen at run time that admission did not know invalidates the analysis of the HRT
// channels whose identifier it beats, and only theirs.
TEST(UndeclaredInterference, NamesTheHrtChannelsAFrameBeats) {
  Config c = native_bus();
  c.channels = {
      native_channel("brake", 0x10, ChannelClass::hrt, NativeCanFrame{0x0F0, false}),
      native_channel("wheel", 0x11, ChannelClass::srt, NativeCanFrame{0x050, false}),
      channel("stop", 0x12, ChannelClass::hrt, {"lan"}, {"body"})};  // extended, priority 0x00: base bits 0x000
  const AdmissionReport report = admit_all(c);
  for (const char* name : {"brake", "wheel", "stop"}) ASSERT_NE(report.find(name)->verdict, Verdict::rejected) << name;
  const std::vector<UnexplainedFrames> seen = {
      {0x0A0, false, 3, 100.0}, {0x1ABCFF00, true, 5, 10.0}, {0x010, false, 1, 0.0}};
  const auto hit = undeclared_interference(report, "body", seen);
  ASSERT_EQ(hit.size(), 1u);  // wheel is SRT; stop's identifier beats them all; 0x010 is silent
  EXPECT_EQ(hit.at("brake"),
            "undeclared frames 0x0A0 at 100.0 Hz win arbitration over its identifier 0x0F0 on body: its response-time "
            "analysis did "
            "not count them (declare them as the segment's background)");
  EXPECT_TRUE(undeclared_interference(report, "lan", seen).empty());
  // A silent frame that wins counts once it sends again.
  EXPECT_EQ(undeclared_interference(report, "body", std::vector<UnexplainedFrames>{{0x010, false, 2, 1.0}}).size(), 1u);
}

}  // namespace
}  // namespace cosmic

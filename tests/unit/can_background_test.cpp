// Background traffic on CAN segments (issue 19, item 1): other ECUs' frames, declared in the YAML
// or taken from a DBC file, enter the response-time analysis of every channel on that bus (by
// their identifiers, standard vs extended arbitration) and its utilization; a channel they push
// past its reaction time names them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "cosmic/admission.hpp"
#include "cosmic/can_background.hpp"
#include "config_test_support.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/report.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;

// A directory of its own per test, removed afterwards: the configuration and its DBC side by side.
class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("cosmic-bg-" + std::to_string(::getpid()) + "-" + std::to_string(++count_))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string write(const std::string& name, const std::string& text) const {
    const auto file = path_ / name;
    std::ofstream(file) << text;
    return file.string();
  }

 private:
  static inline int count_ = 0;
  std::filesystem::path path_;
};

// A body bus: an engine frame (standard 0x0C0, 10 ms), a J1939-style extended frame
// (0x18EFFF01, 100 ms) and an event-driven door message (0x320) with no cycle time.
constexpr const char* kBodyDbc = R"(VERSION ""

NS_ :
	CM_
	BA_DEF_
	BA_

BS_:

BU_: Engine Body

BO_ 192 EngineData: 8 Engine
 SG_ Rpm : 0|16@1+ (0.25,0) [0|16383.75] "rpm" Body
 SG_ Mode M : 16|2@1+ (1,0) [0|3] "" Body
 SG_ Torque m0 : 24|16@1+ (1,0) [0|65535] "Nm" Body

BO_ 2565865217 BodyStatus: 4 Body
 SG_ Lights : 0|8@1+ (1,0) [0|255] "" Engine

BO_ 800 DoorEvent: 2 Body
 SG_ Door : 0|8@1+ (1,0) [0|255] "" Engine

CM_ BO_ 800 "Sent when a door opens; no period; quotes \" and ; inside";
BA_DEF_ BO_ "GenMsgCycleTime" INT 0 65535;
BA_DEF_DEF_ "GenMsgCycleTime" 0;
BA_ "GenMsgCycleTime" BO_ 192 10;
BA_ "GenMsgCycleTime" BO_ 2565865217 100;
)";

std::string config_with(const std::string& background) {
  return R"(gateway: {name: gw, can_node_id: 1, residence_bound: 500us}
segments:
  - name: body
    type: can
    interface: vcan0
    bitrate: 500kbit/s
    max_utilization: 95%
)" + background +
         R"(  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
channels:
  - {name: distance, subject: 0x42, class: hrt, period: 10ms, reaction_time: 5ms, omission_degree: 1, payload: 4B, publishers: [body], subscribers: [lan]}
  - {name: speed, subject: 0x51, class: srt, period: 10ms, reaction_time: 8ms, omission_degree: 1, payload: 8B, publishers: [lan], subscribers: [body]}
)";
}

ConfigResult load(const TempDir& dir, const std::string& background) {
  return load_config_file(dir.write("gw.yaml", config_with(background)));
}

Evaluation admit(const Config& c) { return evaluate(c.gateway, c.segments, c.channels, {}); }

TEST(CanBackgroundConfig, YamlFramesAndTheDbcGiveIdenticalNumbers) {
  TempDir dir;
  dir.write("body.dbc", kBodyDbc);
  const ConfigResult from_dbc = load(dir, "    background: {dbc: body.dbc, periods: {DoorEvent: 50ms}}\n");
  ASSERT_TRUE(from_dbc.ok()) << test::errors_text(from_dbc);
  const ConfigResult from_yaml = load(dir, R"(    background:
      frames:
        - {name: EngineData, can_id: 0x0C0, dlc: 8, period: 10ms}
        - {name: BodyStatus, can_id: 0x18EFFF01, extended: true, dlc: 4, period: 100ms}
        - {name: DoorEvent, can_id: 0x320, length: 2B, period: 50ms}
)");
  ASSERT_TRUE(from_yaml.ok()) << test::errors_text(from_yaml);
  const auto& dbc_frames = from_dbc.config.segments[0].can.background;
  ASSERT_EQ(dbc_frames.size(), 3u);
  EXPECT_EQ(dbc_frames[1].can_id, 0x18EFFF01u);
  EXPECT_TRUE(dbc_frames[1].extended);
  EXPECT_EQ(dbc_frames[2].period, Nanos(50ms));
  EXPECT_NE(dbc_frames[0].origin.find("body.dbc:"), std::string::npos) << dbc_frames[0].origin;
  EXPECT_NE(from_yaml.config.segments[0].can.background[0].origin.find("gw.yaml:"), std::string::npos);
  // Same frames, same analysis: the reports are equal to the byte.
  EXPECT_EQ(to_json(AdmissionReport{admit(from_dbc.config).segments, admit(from_dbc.config).channels}).dump(),
            to_json(AdmissionReport{admit(from_yaml.config).segments, admit(from_yaml.config).channels}).dump());
  EXPECT_EQ(from_dbc.included_files.size(), 1u);
  EXPECT_TRUE(from_yaml.included_files.empty());
}

// cosmicd's reloads skip parsing an unchanged YAML file, but not one that names a DBC: the DBC
// may have changed while the YAML did not.
TEST(CanBackgroundConfig, AReloadReadsTheDbcAgain) {
  TempDir dir;
  dir.write("body.dbc", kBodyDbc);
  const std::string yaml =
      dir.write("gw.yaml", config_with("    background: {dbc: body.dbc, periods: {DoorEvent: 50ms}}\n"));
  ConfigFileLoader loader;
  ASSERT_TRUE(loader.load(yaml).ok());
  std::string faster = kBodyDbc;
  faster.replace(faster.find("BO_ 192 10;"), 11, "BO_ 192 5;");
  dir.write("body.dbc", faster);
  const ConfigResult again = loader.load(yaml);
  ASSERT_TRUE(again.ok()) << test::errors_text(again);
  EXPECT_FALSE(loader.last_was_unchanged());
  EXPECT_EQ(again.config.segments[0].can.background[0].period, Nanos(5ms));
}

TEST(CanBackgroundConfig, ErrorsAreLocatedAndNameTheMessage) {
  TempDir dir;
  dir.write("body.dbc", kBodyDbc);
  // DoorEvent has no cycle time: the error points into the DBC and says what to write.
  ConfigResult r = load(dir, "    background: {dbc: body.dbc}\n");
  ASSERT_EQ(r.errors.size(), 1u) << test::errors_text(r);
  EXPECT_NE(r.errors[0].file.find("body.dbc"), std::string::npos);
  EXPECT_EQ(r.errors[0].line, 20);  // BO_ 800 DoorEvent
  EXPECT_NE(r.errors[0].message.find("DoorEvent (0x320) has no GenMsgCycleTime"), std::string::npos)
      << test::errors_text(r);
  EXPECT_NE(r.errors[0].valid.find("periods: {DoorEvent: 50ms}"), std::string::npos);
  // ignore: leaves it out.
  r = load(dir, "    background: {dbc: body.dbc, ignore: [DoorEvent]}\n");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  EXPECT_EQ(r.config.segments[0].can.background.size(), 2u);
  // Names the DBC does not have, a missing file, periods without a DBC.
  r = load(dir, "    background: {dbc: body.dbc, periods: {DoorEvent: 50ms, Wiper: 1s}, ignore: [Horn]}\n");
  EXPECT_EQ(r.errors.size(), 2u) << test::errors_text(r);
  EXPECT_NE(test::errors_text(r).find("segments[0].background.periods.Wiper: the DBC file"), std::string::npos)
      << test::errors_text(r);
  EXPECT_NE(test::errors_text(r).find("no message named Horn"), std::string::npos) << test::errors_text(r);
  r = load(dir, "    background: {dbc: missing.dbc}\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].line, 8);  // the background line of the YAML
  EXPECT_NE(r.errors[0].message.find("cannot read DBC file"), std::string::npos) << test::errors_text(r);
  r = load(dir, "    background: {dbc: /dev/zero}\n");  // never read from a device or a FIFO
  EXPECT_NE(test::errors_text(r).find("not a regular file"), std::string::npos) << test::errors_text(r);
  r = load(dir, "    background: {periods: {DoorEvent: 50ms}}\n");
  EXPECT_NE(test::errors_text(r).find("periods applies to a DBC's messages"), std::string::npos)
      << test::errors_text(r);
}

TEST(CanBackgroundConfig, FrameValuesAreChecked) {
  TempDir dir;
  const ConfigResult r = load(dir, R"(    background:
      frames:
        - {can_id: 0x800, dlc: 8, period: 10ms}
        - {can_id: 0x20000000, extended: true, dlc: 8, period: 10ms}
        - {can_id: 0x100, dlc: 9, period: 10ms}
        - {can_id: 0x101, length: 12B, period: 10ms}
        - {can_id: 0x102, dlc: 8, period: 0ms}
        - {can_id: 0x103, period: 10ms}
        - {can_id: 0x104, dlc: 1, period: 10ms}
        - {can_id: 0x104, dlc: 2, period: 20ms}
)");
  const std::string text = test::errors_text(r);
  EXPECT_EQ(r.errors.size(), 7u) << text;
  EXPECT_NE(text.find("frames[0].can_id: '0x800' is out of range"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[1].can_id: '0x20000000' is out of range"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[2].dlc"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[3].length: no frame of this bus has 12 data bytes"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[4].period"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[5]: the frame's length is missing"), std::string::npos) << text;
  EXPECT_NE(text.find("frames[7]: identifier 0x104 (0x104) is already declared at"), std::string::npos) << text;
}

// The SRT channel `speed` goes out on the body bus with an extended identifier whose 11 base bits
// are 0x080 (priority 0x10 << 3): standard frames below 0x080 win arbitration over it, those above lose.
std::vector<CanBackgroundFrame> sixteen_frames(std::uint32_t first_id) {
  std::vector<CanBackgroundFrame> frames;
  for (std::uint32_t i = 0; i < 16; ++i) {
    frames.push_back(CanBackgroundFrame{"F" + std::to_string(i), first_id + i, false, 8, Nanos(5ms), Nanos(0), "test",
                                        std::nullopt});
  }
  return frames;
}

Evaluation speed_on_a_bus_with(std::vector<CanBackgroundFrame> background) {
  SegmentSpec body = can_segment("body", 500'000, 0.95);
  body.can.background = std::move(background);
  ChannelSpec speed = channel("speed", 0x51, ChannelClass::srt, {"lan"}, {"body"}, 8, Nanos(10ms), Nanos(4ms));
  return evaluate(gateway(), std::vector<SegmentSpec>{body, dds_segment("lan")}, std::vector<ChannelSpec>{speed}, {});
}

TEST(CanBackgroundAdmission, FramesThatWinArbitrationDelayUsAndAreNamed) {
  // 16 standard 8-byte frames (135 bits = 270 us at 500 kbit/s) every 5 ms: 86.4 % of the bus.
  const Evaluation won = speed_on_a_bus_with(sixteen_frames(0x010));
  const ChannelReport& speed = won.channels[0];
  const HopReport* hop = find_hop(speed, "body");
  ASSERT_NE(hop, nullptr);
  // The gateway's frame (extended, 8 B: 320 us) is released with jitter J = lan's 1 ms + 500 us
  // residence; every background frame is released once in w: w = 16 x 270 us = 4.32 ms;
  // R = J + w + C = 1.5 + 4.32 + 0.32 ms = 6.14 ms > reaction_time 4 ms.
  EXPECT_EQ(hop->can->jitter, Nanos(1'500'000));
  EXPECT_EQ(hop->can->response_time, Nanos(6'140'000));
  EXPECT_EQ(speed.verdict, Verdict::degraded);
  ASSERT_EQ(hop->background.size(), 3u);
  EXPECT_EQ(hop->background[0], (BackgroundDelay{"F0", 0x010, false, Nanos(270'000), false}));
  EXPECT_TRUE(
      has_reason(speed,
                 "R = 6.14 ms > reaction_time 4 ms on body; background frames delaying it most: F0 (0x010) 270 us, "
                 "F1 (0x011) 270 us, F2 (0x012) 270 us"))
      << reasons_text(speed);
  ASSERT_EQ(won.segments.size(), 2u);
  EXPECT_NEAR(won.segments[0].background, 16 * 270.0 / 5000.0, 1e-9);
  EXPECT_EQ(won.segments[0].background_frames, 16u);
  EXPECT_NEAR(won.segments[0].utilization, 16 * 270.0 / 5000.0 + 320.0 / 10000.0, 1e-9);  // ours on top

  // The same load above 0x080 loses arbitration: one frame's blocking (270 us) at most.
  const Evaluation lost = speed_on_a_bus_with(sixteen_frames(0x100));
  const HopReport* blocked = find_hop(lost.channels[0], "body");
  EXPECT_EQ(blocked->can->response_time, Nanos(1'500'000 + 270'000 + 320'000));
  EXPECT_EQ(lost.channels[0].verdict, Verdict::bound) << reasons_text(lost.channels[0]);
  EXPECT_TRUE(blocked->background.empty());
}

TEST(CanBackgroundAdmission, OnEqualBaseBitsTheStandardFrameWins) {
  // A jitter of one period releases a winning frame twice in our queuing delay (2 x 270 us), while
  // a losing one only blocks once (270 us): the two outcomes differ, so the tie rule is what decides.
  // Base bits 0x080 as ours: the standard frame wins the tie (RTR/IDE dominant), so it interferes.
  const Evaluation tie =
      speed_on_a_bus_with({CanBackgroundFrame{"Tie", 0x080, false, 8, Nanos(5ms), Nanos(5ms), "test", std::nullopt}});
  EXPECT_EQ(find_hop(tie.channels[0], "body")->can->response_time, Nanos(1'500'000 + 2 * 270'000 + 320'000));
  // An extended frame with the same base bits and higher low bits than ours loses: it blocks once
  // (0 data bytes, extended: 80 bits = 160 us).
  const Evaluation ext = speed_on_a_bus_with(
      {CanBackgroundFrame{"Ext", (0x080u << 18) | 0x3FFFF, true, 0, Nanos(5ms), Nanos(5ms), "test", std::nullopt}});
  EXPECT_EQ(find_hop(ext.channels[0], "body")->can->response_time, Nanos(1'500'000 + 160'000 + 320'000));
}

TEST(CanBackgroundAdmission, ABusFullOfBackgroundRejectsHrtAndSaysHowFull) {
  SegmentSpec body = can_segment("body", 500'000, 0.70);
  body.can.background = sixteen_frames(0x010);  // 86.4 %
  const ChannelSpec distance =
      channel("distance", 0x42, ChannelClass::hrt, {"body"}, {"lan"}, 4, Nanos(10ms), Nanos(5ms));
  const Evaluation e =
      evaluate(gateway(), std::vector<SegmentSpec>{body, dds_segment("lan")}, std::vector<ChannelSpec>{distance}, {});
  EXPECT_EQ(e.channels[0].verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(e.channels[0], "(background 86.4%) > max_utilization 70.0% on body"))
      << reasons_text(e.channels[0]);
  // Without the background the same channel is bound.
  body.can.background.clear();
  const Evaluation quiet =
      evaluate(gateway(), std::vector<SegmentSpec>{body, dds_segment("lan")}, std::vector<ChannelSpec>{distance}, {});
  EXPECT_EQ(quiet.channels[0].verdict, Verdict::bound) << reasons_text(quiet.channels[0]);
}

TEST(CanBackgroundAdmission, IncrementalBindsAndRemovalsKeepTheBackground) {
  SegmentSpec body = can_segment("body", 500'000, 0.95);
  body.can.background = sixteen_frames(0x010);
  std::vector<SegmentSpec> segments{body, dds_segment("lan")};
  std::vector<ChannelSpec> channels{channel("a", 1, ChannelClass::srt, {"lan"}, {"body"}, 8, Nanos(10ms), Nanos(20ms)),
                                    channel("b", 2, ChannelClass::hrt, {"body"}, {"lan"}, 4, Nanos(20ms), Nanos(30ms))};
  AdmissionSet set(gateway(), segments);
  for (const auto& c : channels) set.commit(set.trial(c, 0));
  const Evaluation whole = evaluate(gateway(), segments, channels, {});
  EXPECT_EQ(to_json(AdmissionReport{set.loads(), set.reports()}).dump(),
            to_json(AdmissionReport{whole.segments, whole.channels}).dump());
  ASSERT_TRUE(set.remove("a"));
  ASSERT_TRUE(set.remove("b"));
  EXPECT_NEAR(set.loads()[0].utilization, 16 * 270.0 / 5000.0, 1e-9);  // back to the background alone
}

}  // namespace
}  // namespace cosmic

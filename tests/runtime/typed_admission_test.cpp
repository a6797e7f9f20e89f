// Admission of typed channels (issue 35, item 3): a hop whose representation cannot carry the
// channel's type (a field without a signal, a frame that is not the DBC message's, a signal
// narrower than a field's range under on_range: drop)
// rejects the channel with the reason on that hop, at start, bind and bind --replace; a signal
// narrower than the range under on_range: saturate degrades it (an HRT channel is rejected). The
// configuration stays loadable, and the other channels are bound and forward.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "typed_fixture.hpp"

namespace cosmic {
namespace {

using namespace typed_test;

const ChannelReport* report_of(const std::vector<ChannelReport>& reports, const std::string& name) {
  const auto it = std::find_if(reports.begin(), reports.end(), [&](const ChannelReport& r) { return r.name == name; });
  return it == reports.end() ? nullptr : &*it;
}

const HopReport* hop_of(const ChannelReport& report, const std::string& segment) {
  const auto it =
      std::find_if(report.hops.begin(), report.hops.end(), [&](const HopReport& h) { return h.segment == segment; });
  return it == report.hops.end() ? nullptr : &*it;
}

const Check* check_of(const HopReport& hop, const std::string& name) {
  const auto it = std::find_if(hop.checks.begin(), hop.checks.end(), [&](const Check& c) { return c.check == name; });
  return it == hop.checks.end() ? nullptr : &*it;
}

std::string reasons_of(const ChannelReport& report) {
  std::string text;
  for (const std::string& reason : report.reasons) text += reason + "\n";
  return text;
}

TEST(TypedConfiguration, AnUntypedRepresentationAndATooSmallPayloadAreConfigurationErrors) {
  const ConfigResult result = parse_with_wheel_dbc(R"(
  - name: untyped
    subject: 3
    class: nrt
    publishers: [viz]
    subscribers: [body]
    native: {viz: {channel: RAW, representation: compact}}
  - name: small
    subject: 4
    class: nrt
    payload: 4B
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [body]
    subscribers: [viz]
)");
  std::map<std::string, std::string> by_path;
  for (const ConfigError& e : result.errors) {
    EXPECT_GT(e.line, 0) << e.to_string();
    by_path[e.path] = e.message;
  }
  ASSERT_EQ(result.errors.size(), 2u) << (result.errors.empty() ? "" : result.errors[0].to_string());
  EXPECT_NE(by_path["channels[0].native.viz.representation"].find("this channel has no type"), std::string::npos);
  EXPECT_NE(by_path["channels[1].payload"].find("payload 4 B is less than an event of the type takes: 10 B"),
            std::string::npos);
}

TEST(TypedAdmission, AHopThatCannotCarryTheTypeRejectsTheChannelWithTheReasonOnThatHop) {
  const ConfigResult result = parse_with_wheel_dbc(R"(
  - name: wrong_id
    subject: 1
    class: nrt
    omission_degree: 1
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [body]
    subscribers: [viz]
    native: {body: {can_id: 0x1A1}}
  - name: json_in
    subject: 2
    class: nrt
    omission_degree: 1
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [viz]
    subscribers: [body]
    native: {viz: {channel: IN, representation: json}}
  - name: wheel
    subject: 3
    class: nrt
    omission_degree: 1
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [body]
    subscribers: [viz]
    native: {body: {can_id: 0x1A0}}
)");
  ASSERT_TRUE(result.ok()) << result.errors[0].to_string();  // loadable: admission judges the hops
  const Config& config = result.config;
  const Evaluation evaluation = evaluate(config.gateway, config.segments, config.channels, {});
  const ChannelReport* wrong_id = report_of(evaluation.channels, "wrong_id");
  ASSERT_NE(wrong_id, nullptr);
  EXPECT_EQ(wrong_id->verdict, Verdict::rejected);
  EXPECT_NE(reasons_of(*wrong_id).find("body cannot carry the channel's type: native frame 0x1A1 is not DBC message "
                                       "WheelSpeed's identifier 0x1A0"),
            std::string::npos)
      << reasons_of(*wrong_id);
  const Check* unfit = check_of(*hop_of(*wrong_id, "body"), "representation");
  ASSERT_NE(unfit, nullptr);
  EXPECT_FALSE(unfit->ok);
  EXPECT_TRUE(check_of(*hop_of(*wrong_id, "viz"), "representation")->ok);  // the reason is on its hop only
  EXPECT_EQ(check_of(*hop_of(*wrong_id, "body"), "frame_fit"), nullptr);   // no size to judge there
  EXPECT_EQ(wrong_id->reasons.size(), 1u) << reasons_of(*wrong_id);
  EXPECT_EQ(hop_of(*wrong_id, "viz")->representation, "compact");
  EXPECT_EQ(hop_of(*wrong_id, "body")->representation, "");

  // JSON is read as well as written: a tool may publish the channel on it (issue 37).
  const ChannelReport* json_in = report_of(evaluation.channels, "json_in");
  ASSERT_NE(json_in, nullptr);
  EXPECT_EQ(json_in->verdict, Verdict::bound) << reasons_of(*json_in);
  EXPECT_EQ(hop_of(*json_in, "viz")->representation, "JSON");
  EXPECT_TRUE(check_of(*hop_of(*json_in, "viz"), "representation")->ok);

  const ChannelReport* wheel = report_of(evaluation.channels, "wheel");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(wheel->verdict, Verdict::bound) << reasons_of(*wheel);
  EXPECT_EQ(hop_of(*wheel, "body")->representation, "DBC frame 0x1A0 WheelSpeed");
  EXPECT_TRUE(check_of(*hop_of(*wheel, "body"), "representation")->ok);
  EXPECT_EQ(check_of(*hop_of(*wheel, "body"), "range"), nullptr);
}

// wheel's chassis hop re-packed into NarrowSpeed, whose Speed signal holds 0..51 km/h of the field's
// 0..655.35.
std::string narrow_config(const std::string& on_range) {
  std::string text = typed_config(on_range);
  const std::string mapped =
      "chassis: {dbc: chassis.dbc, message: VehicleSpeed, map: {Speed: VehicleSpeed, Gear: GearPos}}";
  text.replace(text.find(mapped), mapped.size(), "chassis: {dbc: chassis.dbc, message: NarrowSpeed}");
  // wheel's on_range follows drive's (typed_config sets it there only).
  text.replace(text.find("    publishers: [body]\n    subscribers: [lan, viz, chassis]"), 0,
               "    on_range: " + on_range + "\n");
  return text;
}

constexpr const char* kNarrowed = "signal Speed holds 0..51, narrower than field Speed's range 0..655.35";

TEST_F(TypedForwardingTest, ASignalTooNarrowForTheRangeIsRejectedAtStartAndTheOtherChannelsRun) {
  ConfigResult loaded = load(narrow_config("drop"));
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].to_string();
  const BindResult started = gateway.start(loaded.config);
  const ChannelReport* wheel = report_of(started.channels, "wheel");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(wheel->verdict, Verdict::rejected);
  EXPECT_NE(reasons_of(*wheel).find(std::string("chassis cannot carry the channel's type: message NarrowSpeed: ") +
                                    kNarrowed + "; its events beyond would be dropped"),
            std::string::npos)
      << reasons_of(*wheel);
  // drive is bound and forwards: a compact {Torque 25 Nm, Mode 3} leaves body as its DBC frame.
  std::vector<std::uint8_t> compact;
  const double torque = 25.0;
  put_le(compact, &torque, 8);
  compact.push_back(3);
  ASSERT_TRUE(adapters["lan"]->inject("drive", compact));
  EXPECT_EQ(sent_on("body", 0), (std::vector<std::uint8_t>{10, 3}));
  // wheel is not: no segment carries it.
  EXPECT_FALSE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF, 0x01}));
  EXPECT_TRUE(adapters["lan"]->sent().empty());
}

TEST_F(TypedForwardingTest, ASignalTooNarrowForTheRangeDegradesASaturatingChannelAndSaturates) {
  ConfigResult loaded = load(narrow_config("saturate"));
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].to_string();
  const BindResult started = gateway.start(loaded.config);
  const ChannelReport* wheel = report_of(started.channels, "wheel");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(wheel->verdict, Verdict::degraded) << reasons_of(*wheel);
  EXPECT_NE(reasons_of(*wheel).find(std::string("chassis (DBC frame 0x301 NarrowSpeed of chassis.dbc) saturates "
                                                "values: ") +
                                    kNarrowed),
            std::string::npos)
      << reasons_of(*wheel);
  const Check* range = check_of(*hop_of(*wheel, "chassis"), "range");
  ASSERT_NE(range, nullptr);
  EXPECT_FALSE(range->ok);
  // 123.45 km/h leaves chassis at the signal's limit, 51 km/h (raw 255); Gear -1, Valid 1.
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0x39, 0x30, 0xFF, 0x01}));
  EXPECT_EQ(sent_on("chassis", 0), (std::vector<std::uint8_t>{0xFF, 0x1F}));
}

TEST_F(TypedForwardingTest, AnHrtChannelThatWouldSaturateIsRejected) {
  // wheel as HRT between the two buses only: nothing but the saturating hop can reject it.
  std::string text = narrow_config("saturate");
  text.replace(text.find("class: srt"), 10, "class: hrt");
  const std::string subscribers = "subscribers: [lan, viz, chassis]";
  text.replace(text.find(subscribers), subscribers.size(), "subscribers: [chassis]");
  const std::string json_hop = "      viz: {channel: WHEEL, representation: json}\n";
  text.erase(text.find(json_hop), json_hop.size());
  ConfigResult loaded = load(text);
  ASSERT_TRUE(loaded.ok()) << loaded.errors[0].to_string();
  const Evaluation evaluation =
      evaluate(loaded.config.gateway, loaded.config.segments, loaded.config.channels, {{"wheel", 1}});
  const ChannelReport* wheel = report_of(evaluation.channels, "wheel");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(wheel->verdict, Verdict::rejected);
  ASSERT_EQ(wheel->reasons.size(), 1u) << reasons_of(*wheel);
  EXPECT_NE(reasons_of(*wheel).find(kNarrowed), std::string::npos) << reasons_of(*wheel);
}

// One channel requested, nothing changed, rejected for its chassis hop's too narrow Speed signal.
void expect_rejected_on_chassis(const BindResult& result) {
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 1u);
  EXPECT_EQ(result.channels[0].verdict, Verdict::rejected);
  EXPECT_NE(reasons_of(result.channels[0])
                .find(std::string("chassis cannot carry the channel's type: message "
                                  "NarrowSpeed: ") +
                      kNarrowed),
            std::string::npos)
      << reasons_of(result.channels[0]);
}

TEST_F(TypedForwardingTest, BindAndReplaceRejectAHopThatCannotCarryTheTypeAndChangeNothing) {
  start();
  const std::string file = (dir_ / "bind.yaml").string();
  ChannelsResult extra = parse_channels(R"(
- name: wheel_copy
  subject: 0x20
  class: nrt
  type: {dbc: wheel.dbc, message: WheelSpeed}
  publishers: [lan]
  subscribers: [chassis]
  native: {chassis: {dbc: chassis.dbc, message: NarrowSpeed}}
)",
                                        file, gateway.config());
  ASSERT_TRUE(extra.ok()) << extra.errors[0].to_string();
  expect_rejected_on_chassis(gateway.bind(extra.channels));

  ChannelsResult replacement = parse_channels(R"(
- name: wheel
  subject: 0x10
  class: srt
  period: 10ms
  reaction_time: 50ms
  type: {dbc: wheel.dbc, message: WheelSpeed}
  publishers: [body]
  subscribers: [lan, chassis]
  native: {body: {can_id: 0x1A0}, chassis: {dbc: chassis.dbc, message: NarrowSpeed}}
)",
                                              file, gateway.config());
  ASSERT_TRUE(replacement.ok()) << replacement.errors[0].to_string();
  expect_rejected_on_chassis(gateway.replace(replacement.channels));

  // The running wheel is as it was: its frame still leaves chassis as VehicleSpeed (12.34 km/h is
  // raw 62 of 0.2; Gear -1 in 4 bits; Valid).
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF, 0x01}));
  EXPECT_EQ(sent_on("chassis", 0), (std::vector<std::uint8_t>{0x3E, 0xF0, 0x01}));
}

}  // namespace
}  // namespace cosmic

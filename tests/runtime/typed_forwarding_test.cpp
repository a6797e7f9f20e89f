// Typed channels through the gateway over in-memory segments (issue 35, "each hop in its network's
// own form"): a DBC frame taken on a CAN hop leaves as the compact layout on the gateway's own
// envelope hops and as JSON on a native LCM hop; a compact event leaves a native CAN hop as its DBC
// frame, a value its signal cannot hold dropped (out_of_range) or saturated; an LCM type's encoding
// leaves a native DDS hop as XCDR1; what a hop cannot read is counted as decode_error.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "cosmic/channel_tap.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/control_protocol.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/hop_representation.hpp"
#include "cosmic/lcm_types.hpp"
#include "cosmic/memory_adapter.hpp"
#include "typed_fixture.hpp"

namespace cosmic {
namespace {

using namespace typed_test;

// WheelSpeed {Speed: 12.34, Gear: -1, Valid: true} in the compact layout.
std::vector<std::uint8_t> wheel_speed_12_34_compact() {
  std::vector<std::uint8_t> compact;
  const double speed = 12.34;
  put_le(compact, &speed, 8);
  compact.push_back(0xFF);
  compact.push_back(0x01);
  return compact;
}

TEST_F(TypedForwardingTest, ADbcFrameLeavesAsTheCompactLayoutAndAsJson) {
  start();
  // Speed 12.34 km/h (raw 1234), Gear -1, Valid 1.
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF, 0x01}));
  const std::vector<std::uint8_t> compact = wheel_speed_12_34_compact();
  EXPECT_EQ(sent_on("lan", 0), compact);
  const std::vector<std::uint8_t> json = sent_on("viz", 0);
  EXPECT_EQ(std::string(json.begin(), json.end()), R"({"Speed":12.34,"Gear":-1,"Valid":true})");
}

TEST_F(TypedForwardingTest, AFrameShorterThanItsMessageIsADecodeError) {
  start();
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF}));
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(sent_on("lan", 0).size(), 10u);  // the sound frame passed; the short one did not
  EXPECT_EQ(adapters["lan"]->sent().size(), 1u);
  EXPECT_EQ(dropped("wheel", "body", DropReason::decode_error), 1u);
}

// A tool publishes the channel as JSON on a native LCM hop (issue 37): each text is read into the
// compact layout (its fields in any order) and leaves the envelope hop as such; a text that is not
// one event of the type (a field missing) is counted as decode_error and goes no further.
TEST_F(TypedForwardingTest, JsonATextPublishedOnAnLcmHopIsReadIntoTheCompactLayout) {
  start();
  ChannelsResult json_in = parse_channels(R"(
- name: wheel_in
  subject: 0x21
  class: nrt
  type: {dbc: wheel.dbc, message: WheelSpeed}
  publishers: [viz]
  subscribers: [lan]
  native: {viz: {channel: WHEEL_IN, representation: json}}
)",
                                          (dir_ / "bind.yaml").string(), gateway.config());
  ASSERT_TRUE(json_in.ok()) << json_in.errors[0].to_string();
  const BindResult bound = gateway.bind(json_in.channels);
  ASSERT_TRUE(bound.applied);
  const auto text = [](std::string_view json) { return std::vector<std::uint8_t>(json.begin(), json.end()); };
  ASSERT_TRUE(adapters["viz"]->inject("wheel_in", text(R"({"Speed":12.34,"Gear":-1})")));
  ASSERT_TRUE(adapters["viz"]->inject("wheel_in", text(R"( {"Valid": true, "Gear": -1.0, "Speed": 12.34} )")));
  const std::vector<std::uint8_t> compact = wheel_speed_12_34_compact();
  EXPECT_EQ(sent_on("lan", 0), compact);
  EXPECT_EQ(adapters["lan"]->sent().size(), 1u);
  EXPECT_EQ(dropped("wheel_in", "viz", DropReason::decode_error), 1u);
}

// The envelope hop brings the compact layout: {Torque: float64, Mode: uint8}.
std::vector<std::uint8_t> drive_event(double torque, std::uint8_t mode) {
  std::vector<std::uint8_t> compact;
  put_le(compact, &torque, 8);
  compact.push_back(mode);
  return compact;
}

TEST_F(TypedForwardingTest, ACompactEventLeavesAsItsDbcFrameAndAValueBeyondItsSignalIsDropped) {
  start("drop");
  ASSERT_TRUE(adapters["lan"]->inject("drive", drive_event(100.0, 3)));
  EXPECT_EQ(sent_on("body", 0), (std::vector<std::uint8_t>{40, 3}));
  ASSERT_TRUE(adapters["lan"]->inject("drive", drive_event(700.0, 4)));  // raw 280: beyond 8 bits
  ASSERT_TRUE(adapters["lan"]->inject("drive", drive_event(2.5, 5)));
  EXPECT_EQ(sent_on("body", 1), (std::vector<std::uint8_t>{1, 5}));
  EXPECT_EQ(adapters["body"]->sent().size(), 2u);
  EXPECT_EQ(dropped("drive", "body", DropReason::out_of_range), 1u);
}

TEST_F(TypedForwardingTest, OnRangeSaturateSendsTheNearestValueTheSignalHolds) {
  start("saturate");
  ASSERT_TRUE(adapters["lan"]->inject("drive", drive_event(700.0, 4)));
  EXPECT_EQ(sent_on("body", 0), (std::vector<std::uint8_t>{255, 4}));
  EXPECT_EQ(dropped("drive", "body", DropReason::out_of_range), 0u);
}

TEST_F(TypedForwardingTest, ACompactEventThatIsNotOneOfTheTypeIsADecodeError) {
  start();
  ASSERT_TRUE(adapters["lan"]->inject("drive", {1, 2, 3}));
  ASSERT_TRUE(adapters["lan"]->inject("drive", drive_event(5.0, 1)));
  EXPECT_EQ(sent_on("body", 0), (std::vector<std::uint8_t>{2, 1}));
  EXPECT_EQ(dropped("drive", "lan", DropReason::decode_error), 1u);
}

// demo.pose_t in LCM's encoding (big-endian, the fingerprint first) leaves the native DDS hop as
// XCDR1 little-endian: stamp int64, flags int8, xy double[2] (aligned to 8), n int16, ranges
// sequence<float32, 4> (uint32 count, aligned to 4).
TEST_F(TypedForwardingTest, AnLcmMessageLeavesANativeDdsHopAsXcdr1) {
  start();
  const LcmTypeFile file = parse_lcm_types(kPoseLcm);
  ASSERT_TRUE(file.ok());
  const std::optional<std::uint64_t> fingerprint = lcm_fingerprint(file, *file.find("demo.pose_t"));
  ASSERT_TRUE(fingerprint.has_value());
  std::vector<std::uint8_t> body;
  put_be(body, 1'700'000'000'000'000'000ULL, 8);
  body.push_back(0x80);  // flags -128
  put_be(body, bits_of(1.5), 8);
  put_be(body, bits_of(-2.25), 8);
  put_be(body, 2, 2);  // n
  put_be(body, bits_of(0.5f), 4);
  put_be(body, bits_of(8.0f), 4);
  std::vector<std::uint8_t> wrong(8, 0), message;
  wrong.insert(wrong.end(), body.begin(), body.end());
  put_be(message, *fingerprint, 8);
  message.insert(message.end(), body.begin(), body.end());
  ASSERT_TRUE(adapters["viz"]->inject("pose", wrong));  // another type's fingerprint
  ASSERT_TRUE(adapters["viz"]->inject("pose", message));

  std::vector<std::uint8_t> cdr{0x00, 0x01, 0x00, 0x00};  // CDR_LE, options 0 (48 bytes: no padding)
  const std::int64_t stamp = 1'700'000'000'000'000'000LL;
  put_le(cdr, &stamp, 8);
  cdr.push_back(0x80);
  cdr.insert(cdr.end(), 7, 0);  // xy aligns to 8
  const double xy[2] = {1.5, -2.25};
  put_le(cdr, xy, 16);
  const std::int16_t n = 2;
  put_le(cdr, &n, 2);
  cdr.insert(cdr.end(), 2, 0);  // the sequence's count aligns to 4
  const std::uint32_t count = 2;
  put_le(cdr, &count, 4);
  const float ranges[2] = {0.5f, 8.0f};
  put_le(cdr, ranges, 8);
  EXPECT_EQ(sent_on("lan", 0), cdr);
  EXPECT_EQ(adapters["lan"]->sent().size(), 1u);
  EXPECT_EQ(dropped("pose", "viz", DropReason::decode_error), 1u);
}

TEST(TypedConfiguration, ATypedChannelsPayloadAndHopSizesComeFromItsRepresentations) {
  const ConfigResult result = parse_with_wheel_dbc(R"(
  - name: wheel
    subject: 1
    class: nrt
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [body]
    subscribers: [viz]
    native: {body: {can_id: 0x1A0}}
)");
  ASSERT_TRUE(result.ok()) << result.errors[0].to_string();
  const ChannelSpec& wheel = result.config.channels.at(0);
  EXPECT_EQ(wheel.payload, 10u);            // the compact layout's 8 + 1 + 1, the largest of the hops
  EXPECT_EQ(wheel.payload_on("body"), 4u);  // the DBC frame
  EXPECT_EQ(wheel.payload_on("viz"), 10u);  // the envelope's compact event
  // Written back (a bind or state file) and read again: the same channel.
  ASSERT_TRUE(wheel.type->source->dbc_message.has_value());
  EXPECT_EQ(wheel.type->source->dbc_message->name, "WheelSpeed");
}

// cosmicctl echo's requests: a tap on a typed channel shows each admitted event's fields, decoded.
TEST_F(TypedForwardingTest, EchoShowsATypedChannelsEventsDecoded) {
  start();
  ControlProtocol control(
      gateway, [] { return ConfigResult{}; }, AccessPolicy{}, log);
  const PeerCredentials peer{};
  const auto ask = [&](const nlohmann::json& request) {
    return nlohmann::json::parse(control.handle(request.dump(), peer));
  };
  const nlohmann::json opened = ask({{"command", "echo_open"}, {"name", "wheel"}});
  ASSERT_TRUE(opened["ok"].get<bool>()) << opened.dump();
  EXPECT_EQ(opened["type"], "{Speed: float64 [km/h, 0..655.35], Gear: int8 [-1..6], Valid: bool [0..1]}");
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF, 0x01}));
  ASSERT_EQ(sent_on("lan", 0).size(), 10u);  // admitted (and tapped) before it was queued
  const nlohmann::json read = ask({{"command", "echo_read"}, {"tap", opened["tap"]}});
  ASSERT_TRUE(read["ok"].get<bool>()) << read.dump();
  ASSERT_EQ(read["events"].size(), 1u) << read.dump();
  EXPECT_EQ(read["events"][0]["contents"], nlohmann::json::parse(R"({"Speed":12.34,"Gear":-1,"Valid":true})"));
  EXPECT_EQ(read["events"][0]["sequence"], 1);  // as the gateway numbered it for its subscribers
  EXPECT_EQ(read["events"][0]["origin"], 0x4321);
  EXPECT_EQ(read["missed"], 0);
  EXPECT_TRUE(ask({{"command", "echo_close"}, {"tap", opened["tap"]}})["ok"].get<bool>());
  const nlohmann::json after = ask({{"command", "echo_read"}, {"tap", opened["tap"]}});
  EXPECT_EQ(after["error"]["code"], "not_found");
  EXPECT_EQ(ask({{"command", "echo_open"}, {"name", "nothing"}})["error"]["code"], "not_found");
  EXPECT_EQ(ask({{"command", "echo_read"}})["error"]["code"], "not_found");
}

// The tap is bounded: a full one counts what it could not take, and forwarding goes on.
TEST(ChannelTap, AFullTapCountsWhatItMissedAndAClosedOneTakesNothing) {
  TapBoard board;
  const EventHeader header{};
  const std::vector<std::uint8_t> bytes{1, 2, 3};
  board.offer(7, header, Nanos(0), bytes);  // no tap open: nothing to do
  const std::optional<std::uint32_t> tap = board.open(7, 3);
  ASSERT_TRUE(tap.has_value());
  for (std::size_t i = 0; i < TapBoard::kSlotsPerTap + 5; ++i) board.offer(7, header, Nanos(0), bytes);
  board.offer(8, header, Nanos(0), bytes);                            // another channel's
  board.offer(7, header, Nanos(0), std::vector<std::uint8_t>(4, 0));  // larger than the slots
  std::optional<TapRead> read = board.read(*tap);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->events.size(), TapBoard::kSlotsPerTap);
  EXPECT_EQ(read->missed, 6u);
  EXPECT_EQ(read->events[0].payload, bytes);
  board.close(*tap);
  EXPECT_EQ(board.open_taps(), 0u);
  EXPECT_FALSE(board.read(*tap).has_value());
  std::vector<std::uint32_t> ids;
  for (std::size_t i = 0; i < TapBoard::kMaxTaps; ++i) ids.push_back(board.open(1, 8).value_or(0));
  EXPECT_FALSE(board.open(1, 8).has_value());  // every tap in use
  EXPECT_EQ(std::set<std::uint32_t>(ids.begin(), ids.end()).size(), TapBoard::kMaxTaps);
}

// BrakeStatus with its E2E counter and CRC (profile 1, data ID 0x0123, both bytes): the CRCs below
// are python3-crcmod's (mkCrcFun(0x11D, initCrc=0, xorOut=0)) over 23 01, the counter byte and the
// pressure, not this code's.
std::vector<std::uint8_t> brake_frame(std::uint8_t crc, std::uint8_t counter, std::uint16_t pressure) {
  return {crc, counter, static_cast<std::uint8_t>(pressure & 0xFF), static_cast<std::uint8_t>(pressure >> 8)};
}

TEST_F(TypedForwardingTest, AnE2eFrameIsCheckedAndItsCounterGapsCountAgainstTheOmissionDegree) {
  start();
  const auto inject = [&](std::vector<std::uint8_t> frame) { ASSERT_TRUE(adapters["body"]->inject("brake", frame)); };
  inject(brake_frame(0x50, 0, 100));  // counter 0
  inject(brake_frame(0x93, 1, 101));  // 1
  inject(brake_frame(0x08, 3, 103));  // 3: counter 2 never came (1 omitted, within the degree)
  inject(brake_frame(0x08, 3, 103));  // 3 again: a repeat
  inject(brake_frame(0x20, 4, 104));  // a wrong CRC (0x21 is right)
  inject(brake_frame(0x79, 7, 107));  // 7: 4, 5 and 6 missing (the corrupt 4 never counted as received)
  // The type leaves the counter and CRC out: the lan hop gets Pressure alone (uint16, the compact layout).
  for (std::size_t i = 0; i < 4; ++i) {
    const std::uint16_t expected[] = {100, 101, 103, 107};
    EXPECT_EQ(sent_on("lan", i), (std::vector<std::uint8_t>{static_cast<std::uint8_t>(expected[i] & 0xFF),
                                                            static_cast<std::uint8_t>(expected[i] >> 8)}))
        << i;
  }
  const auto stats = gateway.channel_stats();
  const SegmentCountersSnapshot* body = hop(stats, "brake", "body");
  ASSERT_NE(body, nullptr);
  EXPECT_EQ(body->rx, 6u);
  EXPECT_EQ(body->dropped[static_cast<std::size_t>(DropReason::duplicate)], 1u);
  EXPECT_EQ(body->dropped[static_cast<std::size_t>(DropReason::corrupt)], 1u);
  EXPECT_EQ(body->omitted, 4u);
  EXPECT_EQ(body->omission_excess, 1u);  // the gap of 3 is beyond omission_degree 1; the gap of 1 is not
  // A gap beyond the omission degree turns the channel violated (an NRT channel too), with the numbers.
  gateway.refresh_runtime(Nanos(1'000'000'000));
  const auto after = gateway.channel_stats();
  const auto brake = std::find_if(after.begin(), after.end(), [](const auto& c) { return c.name == "brake"; });
  ASSERT_NE(brake, after.end());
  EXPECT_EQ(brake->runtime_state, RuntimeState::violated);
  const bool logged = std::any_of(log.lines.begin(), log.lines.end(), [](const std::string& line) {
    return line.find(
               "channel brake violated its omission degree 1: hop body: 1 gaps in the end-to-end counter "
               "longer than that, 4 events missing in all;") != std::string::npos;
  });
  EXPECT_TRUE(logged);
}

TEST_F(TypedForwardingTest, AnE2eFrameLeavesWithItsOwnCounterAndCrc) {
  start();
  for (std::uint16_t pressure : {500, 501, 502}) {
    ASSERT_TRUE(adapters["lan"]->inject(
        "brake_command", {static_cast<std::uint8_t>(pressure & 0xFF), static_cast<std::uint8_t>(pressure >> 8)}));
  }
  // data_id_mode low: crcmod over 24, the counter byte and the pressure.
  EXPECT_EQ(sent_on("body", 0), (std::vector<std::uint8_t>{0xD6, 0, 0xF4, 0x01}));
  EXPECT_EQ(sent_on("body", 1), (std::vector<std::uint8_t>{0x15, 1, 0xF5, 0x01}));
  EXPECT_EQ(sent_on("body", 2), (std::vector<std::uint8_t>{0x4D, 2, 0xF6, 0x01}));
}

// The signal gateway (AUTOSAR COM's, CAN to CAN): WheelSpeed's fields re-packed into the chassis
// bus's VehicleSpeed by name and by `map`; python3-canmatrix decodes 3E F0 01 with chassis.dbc as
// VehicleSpeed 12.4 km/h, GearPos -1, Valid 1 (Speed 12.34 to the signal's 0.2 km/h step).
TEST_F(TypedForwardingTest, ADbcFrameIsRepackedIntoAnotherBussMessage) {
  start();
  ASSERT_TRUE(adapters["body"]->inject("wheel", {0xD2, 0x04, 0xFF, 0x01}));
  EXPECT_EQ(sent_on("chassis", 0), (std::vector<std::uint8_t>{0x3E, 0xF0, 0x01}));
  // Admission counts the chassis hop at VehicleSpeed's 3 bytes; cosmicctl channel names its form.
  const ChannelSpec* wheel = gateway.config().find_channel("wheel");
  ASSERT_NE(wheel, nullptr);
  EXPECT_EQ(wheel->payload_on("chassis"), 3u);
  const auto form = hop_representation(*wheel, *gateway.config().find_segment("chassis"));
  ASSERT_TRUE(form.ok());
  EXPECT_EQ(form.value()->describe(), "DBC frame 0x300 VehicleSpeed of chassis.dbc");
}

}  // namespace
}  // namespace cosmic

// The signal gateway's codec (issue 35; DbcFrameCodec::make_mapped, cosmic/dbc_frames.hpp): a typed
// channel's fields packed into another DBC message's signals by name and by map, and everything it
// refuses, each reason naming the field.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/dbc_type.hpp"

#include "dbc_test_support.hpp"

namespace cosmic {
namespace {

constexpr std::string_view kGatewayDbc = R"dbc(BO_ 416 Wheel: 4 Ecu
 SG_ Speed : 0|16@1+ (0.01,0) [0|655.35] "km/h" Gateway
 SG_ Gear : 16|8@1- (1,0) [-1|6] "" Gateway
 SG_ State : 24|2@1+ (1,0) [0|3] "" Gateway
BO_ 768 Cluster: 4 Gateway
 SG_ ClusterSpeed : 0|12@1+ (0.2,0) [0|0] "km/h" Dash
 SG_ Gear : 12|4@1- (1,0) [0|0] "" Dash
 SG_ State : 16|2@1+ (1,0) [0|0] "" Dash
BO_ 769 Muxed: 4 Gateway
 SG_ Mode M : 0|8@1+ (1,0) [0|0] "" Dash
 SG_ Speed m0 : 8|16@1+ (0.01,0) [0|0] "" Dash
BO_ 770 Odd: 4 Gateway
 SG_ Speed : 0|16@1+ (0.01,0) [0|0] "" Dash
 SG_ Gear : 16|8@1- (0.5,0) [0|0] "" Dash
 SG_ State : 24|1@1+ (1,0) [0|0] "" Dash
 SG_ Float : 0|32@1+ (1,0) [0|0] "" Dash
VAL_ 416 State 0 "Off" 1 "On" 3 "Fault" ;
SIG_VALTYPE_ 770 Float : 1;
)dbc";

const DbcMessage& gateway_message(const std::string& name) {
  static const DbcFile file = parse_dbc(kGatewayDbc);
  return test::message_named(file, name);
}

ChannelType wheel_type() { return channel_type_from_dbc(gateway_message("Wheel")).type; }

std::string refusal(const std::string& message, const std::map<std::string, std::string>& map) {
  const Result<DbcFrameCodec> codec = DbcFrameCodec::make_mapped(gateway_message(message), wheel_type(), map);
  return codec.ok() ? "accepted" : codec.error().text;
}

TEST(DbcSignalGateway, FieldsGoIntoTheSignalsOfTheirNameOrTheirMap) {
  const ChannelType type = wheel_type();
  const Result<DbcFrameCodec> codec =
      DbcFrameCodec::make_mapped(gateway_message("Cluster"), type, {{"Speed", "ClusterSpeed"}});
  ASSERT_TRUE(codec.ok()) << codec.error().text;
  const Result<DbcFrameCodec> own = DbcFrameCodec::make(gateway_message("Wheel"), type);
  ASSERT_TRUE(own.ok());
  // Speed 100.00 km/h (raw 10000), Gear -1, State Fault (3).
  const std::vector<std::uint8_t> wheel = {0x10, 0x27, 0xFF, 0x03};
  std::vector<std::uint8_t> event(own.value().compact_size());
  ASSERT_TRUE(own.value().to_compact(wheel, event));
  std::vector<std::uint8_t> cluster(4);
  const DbcFrameCodec::Packed packed = codec.value().to_frame(event, cluster, RangePolicy::drop);
  ASSERT_TRUE(packed.sent);
  // ClusterSpeed 500 (100 / 0.2) in bits 0-11, Gear -1 (0xF) in 12-15, State 3 in 16-17.
  EXPECT_EQ(cluster, (std::vector<std::uint8_t>{0xF4, 0xF1, 0x03, 0x00}));
  // And back: the cluster's frame as the channel's event.
  std::vector<std::uint8_t> again(own.value().compact_size());
  ASSERT_TRUE(codec.value().to_compact(cluster, again));
  EXPECT_EQ(again, event);
}

TEST(DbcSignalGateway, WhatCannotBeCarriedIsRefusedNamingTheField) {
  EXPECT_EQ(refusal("Cluster", {}),
            "field Speed has no signal Speed in message Cluster (map: {Speed: SIGNAL} names "
            "the one that carries it, omit: [Speed] leaves it out)");
  EXPECT_EQ(refusal("Cluster", {{"Speed", "Nothing"}}), "field Speed has no signal Nothing in message Cluster");
  EXPECT_EQ(refusal("Cluster", {{"Speed", "ClusterSpeed"}, {"Torque", "Gear"}}),
            "map names field Torque, which the channel's type does not have");
  EXPECT_EQ(refusal("Cluster", {{"Speed", "ClusterSpeed"}, {"State", "Gear"}}),
            "fields Gear and State are both mapped to signal Gear");
  EXPECT_EQ(refusal("Muxed", {}),
            "message Muxed is multiplexed: the signal gateway re-packs messages without "
            "multiplexing");
  EXPECT_EQ(refusal("Odd", {}),
            "message Odd: field Gear is an integer, and signal Gear's scaling (0.5, 0) is not whole");
  EXPECT_EQ(refusal("Odd", {{"Gear", "Float"}}),
            "message Odd: field Gear is an integer, and signal Float an IEEE float");
  EXPECT_EQ(refusal("Odd", {{"Speed", "Gear"}, {"Gear", "Float"}}),
            "message Odd: field Gear is an integer, and signal Float an IEEE float");
  EXPECT_EQ(refusal("Odd", {{"Gear", "Gear"}, {"Speed", "Float"}, {"State", "State"}}),
            "message Odd: field Gear is an integer, and signal Gear's scaling (0.5, 0) is not whole");
}

// A ROS 2 Twist: {linear: {x, y, z}, angular: {x, y, z}}, float64 each.
ChannelType twist_type() {
  TypeField number{"x", FieldType{}, "", std::nullopt, std::nullopt, std::nullopt};
  FieldType vector3;
  vector3.kind = FieldType::Kind::record;
  for (const char* axis : {"x", "y", "z"}) {
    number.name = axis;
    vector3.fields.push_back(number);
  }
  ChannelType twist;
  twist.fields.push_back(TypeField{"linear", vector3, "", std::nullopt, std::nullopt, std::nullopt});
  twist.fields.push_back(TypeField{"angular", vector3, "", std::nullopt, std::nullopt, std::nullopt});
  return twist;
}

constexpr std::string_view kDriveDbc = R"dbc(BO_ 528 DriveCommand: 4 Gateway
 SG_ Speed : 0|16@1- (0.001,0) [-32.768|32.767] "m/s" Drive
 SG_ YawRate : 16|16@1- (0.001,0) [-32.768|32.767] "rad/s" Drive
)dbc";

// A nested record's numbers map by their paths, and `omit` leaves the others out: a Twist command
// becomes a drive ECU's frame and back.
TEST(DbcSignalGateway, ANestedRecordsNumbersMapByTheirPathsAndOmittedOnesStayOut) {
  static const DbcFile file = parse_dbc(kDriveDbc);
  const DbcMessage& drive = test::message_named(file, "DriveCommand");
  const std::vector<std::string> omitted = {"linear.y", "linear.z", "angular.x", "angular.y"};
  const Result<DbcFrameCodec> codec =
      DbcFrameCodec::make_mapped(drive, twist_type(), {{"linear.x", "Speed"}, {"angular.z", "YawRate"}}, omitted);
  ASSERT_TRUE(codec.ok()) << codec.error().text;
  ASSERT_EQ(codec.value().compact_size(), 48u);
  const double twist[6] = {1.5, 7.0, 7.0, 7.0, 7.0, -0.25};  // linear.x 1.5 m/s, angular.z -0.25 rad/s
  std::vector<std::uint8_t> event(48);
  std::memcpy(event.data(), twist, sizeof twist);
  std::vector<std::uint8_t> frame(4);
  ASSERT_TRUE(codec.value().to_frame(event, frame, RangePolicy::drop).sent);
  EXPECT_EQ(frame, (std::vector<std::uint8_t>{0xDC, 0x05, 0x06, 0xFF}));  // raw 1500, raw -250
  std::vector<std::uint8_t> back(48);
  ASSERT_TRUE(codec.value().to_compact(frame, back));
  double values[6];
  std::memcpy(values, back.data(), sizeof values);
  EXPECT_EQ(std::vector<double>(values, values + 6), (std::vector<double>{1.5, 0, 0, 0, 0, -0.25}));

  EXPECT_EQ(
      DbcFrameCodec::make_mapped(drive, twist_type(), {{"linear.x", "Speed"}, {"angular.z", "YawRate"}}).error().text,
      "field linear.y has no signal linear.y in message DriveCommand (map: {linear.y: SIGNAL} names the one "
      "that carries it, omit: [linear.y] leaves it out)");
  EXPECT_EQ(DbcFrameCodec::make_mapped(drive, twist_type(), {{"linear.x", "Speed"}}, {"linear.x"}).error().text,
            "field linear.x is both mapped and omitted");
  EXPECT_EQ(DbcFrameCodec::make_mapped(drive, twist_type(), {}, {"linear.w"}).error().text,
            "omit names field linear.w, which the channel's type does not have");
}

// A narrower signal is no refusal of the codec: the hop decides (refused under on_range: drop,
// saturated and degraded otherwise; cosmic/hop_representation.hpp), so the codec names it.
TEST(DbcSignalGateway, ASignalNarrowerThanItsFieldsRangeIsNamedAndItsValuesSaturate) {
  ChannelType speed_only = wheel_type();
  speed_only.fields.resize(1);  // Speed: float64, 0..655.35 km/h
  const Result<DbcFrameCodec> codec =
      DbcFrameCodec::make_mapped(gateway_message("Odd"), speed_only, {{"Speed", "Gear"}});
  ASSERT_TRUE(codec.ok()) << codec.error().text;
  EXPECT_EQ(codec.value().narrowed(),
            (std::vector<std::string>{"signal Gear holds -64..63.5, narrower than field Speed's range 0..655.35"}));
  const double speed = 100.0;
  std::vector<std::uint8_t> event(codec.value().compact_size());
  std::memcpy(event.data(), &speed, sizeof speed);
  std::vector<std::uint8_t> odd(4);
  EXPECT_FALSE(codec.value().to_frame(event, odd, RangePolicy::drop).sent);
  const DbcFrameCodec::Packed saturated = codec.value().to_frame(event, odd, RangePolicy::saturate);
  ASSERT_TRUE(saturated.sent);
  EXPECT_EQ(saturated.out_of_range, 1u);
  EXPECT_EQ(odd, (std::vector<std::uint8_t>{0x00, 0x00, 0x7F, 0x00}));  // Gear at 63.5 (raw 127)
  const Result<DbcFrameCodec> wide =
      DbcFrameCodec::make_mapped(gateway_message("Cluster"), speed_only, {{"Speed", "ClusterSpeed"}});
  ASSERT_TRUE(wide.ok());
  EXPECT_TRUE(wide.value().narrowed().empty());
}

TEST(DbcSignalGateway, AnEnumerationNeedsEveryValueInItsSignal) {
  const Result<DbcFrameCodec> codec = DbcFrameCodec::make_mapped(
      gateway_message("Odd"), wheel_type(), {{"Speed", "Float"}, {"Gear", "Gear"}, {"State", "State"}});
  EXPECT_FALSE(codec.ok());
  ChannelType type = wheel_type();
  type.fields.erase(type.fields.begin() + 1);  // Gear
  const Result<DbcFrameCodec> one_bit = DbcFrameCodec::make_mapped(gateway_message("Odd"), type, {{"Speed", "Float"}});
  ASSERT_FALSE(one_bit.ok());
  EXPECT_EQ(one_bit.error().text, "message Odd: signal State holds raw values 0..1, not field State's value Fault = 3");
}

}  // namespace
}  // namespace cosmic

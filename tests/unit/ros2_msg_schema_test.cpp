// The ROS 2 message definition of a channel type (cosmic/ros2_msg_schema.hpp, issue 37): the exact
// text for a type with every kind of field, the names it gives, and what it refuses. That
// @foxglove/rosmsg2-serialization decodes CdrRepresentation's bytes with this text to the values
// sent is tests/mcap (mcap.npm_decodes_cdr) and daemon.recording.
#include "cosmic/ros2_msg_schema.hpp"

#include <gtest/gtest.h>

#include <string>

#include "ros2_msg_test_types.hpp"

namespace cosmic {
namespace {

using namespace schema_test;
using K = ScalarKind;

const std::string kSeparator(80, '=');

std::string refusal(const ChannelType& type) {
  const auto schema = ros2_msg_schema(type, "refused");
  EXPECT_FALSE(schema.ok());
  return schema.ok() ? std::string() : schema.error().text;
}

TEST(Ros2MsgSchema, TheExactDefinitionOfATypeWithEveryKind) {
  const auto schema = ros2_msg_schema(ros2_msg_test::every_kind(), "every-kind");
  ASSERT_TRUE(schema.ok()) << schema.error().text;
  EXPECT_EQ(schema.value().name, "cosmic/msg/EveryKind");
  std::string expected =
      "bool flag\n"
      "int8 i8\n"
      "int16 i16 # [degC]\n"
      "int32 i32\n"
      "int64 i64\n"
      "uint8 u8\n"
      "uint16 u16\n"
      "uint32 u32 # [ms]\n"
      "uint64 u64\n"
      "float32 f32 # [m/s]\n"
      "float64 f64 # [m]\n"
      "int8 OFF=-1\n"
      "int8 IDLE=0\n"
      "int8 RUN=1\n"
      "int8 state\n"
      "uint64 LOW=0\n"
      "uint64 HUGE=1152921504606846976\n"
      "uint64 gear\n"
      "string<=8 label\n"
      "float32[4] ranges # [m]\n"
      "# grid: 2 x 3 elements, row after row (one flat array: the same CDR bytes)\n"
      "uint8[6] grid\n"
      "int16[<=3] track\n"
      "cosmic/EveryKindPose pose\n"
      "cosmic/EveryKindPath[<=2] path\n"
      "uint8 mode\n"
      "int32 FORWARD=1\n"
      "int32 REVERSE=-1\n"
      "int32 direction\n"
      "uint8 power\n"  // OFF is state's already: no constants
      "cosmic/EveryKindFix fix\n"
      "cosmic/EveryKindCorners[2] corners\n"
      "string<=5[2] names\n"
      "bool[<=4] flags\n";
  expected += kSeparator + "\n" +
              "MSG: cosmic/EveryKindPose\n"
              "float64 x # [m]\n"
              "float64 y # [m]\n"
              "float32 heading # [rad]\n";
  expected += kSeparator + "\n" +
              "MSG: cosmic/EveryKindPath\n"
              "string<=4 name\n"
              "uint32 stamp\n";
  expected += kSeparator + "\n" +
              "MSG: cosmic/EveryKindFix\n"
              "cosmic/EveryKindFixOrigin origin\n"
              "uint8 quality\n";
  expected += kSeparator + "\n" +
              "MSG: cosmic/EveryKindFixOrigin\n"
              "float64 lat\n"
              "float64 lon\n";
  expected += kSeparator + "\n" +
              "MSG: cosmic/EveryKindCorners\n"
              "int16 x\n"
              "uint8 OFF=0\n"
              "uint8 ON=1\n"
              "uint8 light\n";
  EXPECT_EQ(schema.value().text, expected);
}

TEST(Ros2MsgSchema, AChannelNameBecomesAMessageNameInCamelCase) {
  const ChannelType type = channel_type({field("x", scalar(K::float64))});
  EXPECT_EQ(ros2_msg_schema(type, "range").value().name, "cosmic/msg/Range");
  EXPECT_EQ(ros2_msg_schema(type, "front_left.wheel-speed").value().name, "cosmic/msg/FrontLeftWheelSpeed");
  // A message name begins with a capital letter.
  EXPECT_EQ(ros2_msg_schema(type, "2d-scan").value().name, "cosmic/msg/Channel2dScan");
}

TEST(Ros2MsgSchema, ATypeFromARos2MessageKeepsItsName) {
  ChannelType type = channel_type({field("pose", record({field("x", scalar(K::float64))}))});
  type.source = TypeSource{};
  type.source->format = TypeSource::Format::msg;
  type.source->name = "nav_msgs/msg/Odometry";
  const auto schema = ros2_msg_schema(type, "odom");
  ASSERT_TRUE(schema.ok()) << schema.error().text;
  EXPECT_EQ(schema.value().name, "nav_msgs/msg/Odometry");
  // Nested records have no names of their own in a channel type: named after their place.
  EXPECT_EQ(schema.value().text,
            "nav_msgs/OdometryPose pose\n" + kSeparator + "\nMSG: nav_msgs/OdometryPose\nfloat64 x\n");
}

TEST(Ros2MsgSchema, TwoPlacesThatGiveTheSameNameGetTwoNames) {
  // a.b_c and a_b.c both read TopABC.
  const FieldType leaf = record({field("x", scalar(K::uint8))});
  const ChannelType type =
      channel_type({field("a", record({field("b_c", leaf)})), field("a_b", record({field("c", leaf)}))});
  const auto schema = ros2_msg_schema(type, "top");
  ASSERT_TRUE(schema.ok()) << schema.error().text;
  const std::string& text = schema.value().text;
  EXPECT_NE(text.find("MSG: cosmic/TopABC\n"), std::string::npos) << text;
  EXPECT_NE(text.find("MSG: cosmic/TopABC2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("cosmic/TopABC2 c\n"), std::string::npos) << text;
}

TEST(Ros2MsgSchema, AUnitThatIsNotPlainAsciiIsLeftOut) {
  const ChannelType type = channel_type({field("t", scalar(K::float32),
                                               {.unit = "\xB0"
                                                        "C"}),
                                         field("u", scalar(K::float32), {.unit = "m[1]"})});
  EXPECT_EQ(ros2_msg_schema(type, "temp").value().text, "float32 t\nfloat32 u\n");
}

TEST(Ros2MsgSchema, RefusesAConditionalField) {
  const ChannelType type = channel_type(
      {field("mode", scalar(K::uint8)), field("dtc", scalar(K::uint16), {.present_when = FieldPresence{"mode", 0}})});
  EXPECT_EQ(refusal(type),
            "field dtc is conditional (present_when, a DBC message's multiplexed signal): a ROS 2 "
            "message has no such field, so the type has no CDR form");
}

TEST(Ros2MsgSchema, RefusesAFieldNameRos2DoesNotAllow) {
  for (const char* name : {"Speed", "vehicleSpeed", "a__b", "speed_", "x9_Y"}) {
    EXPECT_EQ(refusal(channel_type({field(name, scalar(K::float32))})),
              std::string("field ") + name +
                  " is not a ROS 2 field name ([a-z][a-z0-9_]*, without \"__\", not ending in '_')");
  }
  // Found where it is nested.
  EXPECT_EQ(refusal(channel_type({field("pose", record({field("X", scalar(K::float64))}))})).substr(0, 14),
            "field pose.X i");
  EXPECT_TRUE(valid_ros2_field_name("wheel_speed_2"));
  EXPECT_FALSE(valid_ros2_field_name("_x"));
}

TEST(Ros2MsgSchema, RefusesCollectionsMsgCannotWrite) {
  EXPECT_EQ(refusal(channel_type({field("rows", array(sequence(scalar(K::uint8), 4), 2))})),
            "field rows is an array of sequences, which .msg cannot write");
  EXPECT_EQ(refusal(channel_type({field("rows", sequence(array(scalar(K::uint8), 4), 2))})),
            "field rows is a sequence of arrays or sequences, which .msg cannot write");
  EXPECT_EQ(refusal(channel_type({field("rows", sequence(sequence(scalar(K::uint8), 4), 2))})),
            "field rows is a sequence of arrays or sequences, which .msg cannot write");
}

TEST(Ros2MsgSchema, RefusesATypeThatIsNotSound) {
  EXPECT_EQ(refusal(channel_type({})).substr(0, 22), "the type is not sound:");
}

}  // namespace
}  // namespace cosmic

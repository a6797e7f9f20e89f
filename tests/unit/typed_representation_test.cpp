// Typed events between representations (issue 35): the compact layout (cosmic/compact_layout.hpp)
// checked and read, a DBC message's frames to and from it (cosmic/dbc_frames.hpp) with whole-number
// scaling, multiplexing and the range policy, and JSON for tools (cosmic/json_representation.hpp).
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/json_representation.hpp"

namespace cosmic {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::string_view kDbc = R"dbc(BO_ 256 BodyStatus: 8 Ecu
 SG_ Ignition : 0|2@1+ (1,0) [0|3] "" Gateway
 SG_ BatteryVoltage : 8|16@1+ (0.01,0) [0|655.35] "V" Gateway
 SG_ AmbientTemp : 24|8@1- (0.5,-40) [-104|23.5] "degC" Gateway
 SG_ Odometer : 32|20@1+ (10,-100) [0|0] "m" Gateway
 SG_ Brake : 52|1@1+ (1,0) [0|1] "" Gateway
BO_ 2566844672 Diagnostics: 8 Gateway
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|65535] "" Ecu
 SG_ Pressure m2 : 8|32@1- (1,0) [0|0] "bar" Ecu
VAL_ 256 Ignition 0 "Off" 1 "Accessory" 2 "Run" ;
SIG_VALTYPE_ 2566844672 Pressure : 1;
)dbc";

struct Typed {
  DbcMessage message;
  ChannelType type;
};

Typed typed(std::size_t index) {
  const DbcFile file = parse_dbc(kDbc);
  EXPECT_TRUE(file.ok());
  const DbcMessage& m = file.messages.at(index);
  return Typed{m, channel_type_from_dbc(m).type};
}

std::string json_of(const ChannelType& type, const Bytes& compact) {
  const JsonRepresentation json{ChannelType(type)};
  std::string out(json.max_size(), '\0');
  const auto size = json.write(compact, std::span<char>(out.data(), out.size()));
  return size ? out.substr(0, *size) : "<not an event>";
}

TEST(CompactLayout, FlatRecordSlotsAndChecks) {
  const Typed body = typed(0);
  const auto layout = CompactLayout::of_flat_record(body.type);
  ASSERT_TRUE(layout.ok()) << layout.error().text;
  // enum uint8, float64, float64, int32, bool.
  EXPECT_EQ(layout.value().size(), 1u + 8 + 8 + 4 + 1);
  EXPECT_EQ(layout.value().slots()[3].offset, 17u);
  EXPECT_EQ(max_compact_size(body.type), 22u);
  EXPECT_TRUE(check_compact(body.type, Bytes(22)).ok());
  EXPECT_EQ(check_compact(body.type, Bytes(21)).error().text, "Brake: the event ends inside it");
  EXPECT_EQ(check_compact(body.type, Bytes(23)).error().text, "the event has 1 bytes after its last field");
  Bytes bad_bool(22);
  bad_bool[21] = 2;
  EXPECT_EQ(check_compact(body.type, bad_bool).error().text, "Brake: a bool is 0 or 1, not 2");
}

TEST(CompactLayout, StringsAndSequencesCarryTheirCountWithinTheBound) {
  ChannelType type;
  TypeField label;
  label.name = "label";
  label.type.kind = FieldType::Kind::string;
  label.type.bound = 4;
  TypeField track;
  track.name = "track";
  track.type.kind = FieldType::Kind::sequence;
  track.type.bound = 2;
  FieldType element;
  element.scalar = ScalarKind::int16;
  track.type.element = {element};
  type.fields = {label, track};
  EXPECT_EQ(max_compact_size(type), 4u + 4 + 4 + 2 * 2);
  const Bytes ok{2, 0, 0, 0, 'h', 'i', 1, 0, 0, 0, 0xFF, 0xFF};
  EXPECT_TRUE(check_compact(type, ok).ok());
  EXPECT_EQ(json_of(type, ok), R"({"label":"hi","track":[-1]})");
  const Bytes long_label{5, 0, 0, 0, 'h', 'e', 'l', 'l', 'o', 0, 0, 0, 0};
  EXPECT_EQ(check_compact(type, long_label).error().text, "label: 5 bytes, more than its bound 4");
  const Bytes long_track{0, 0, 0, 0, 3, 0, 0, 0, 1, 0, 2, 0, 3, 0};
  EXPECT_EQ(check_compact(type, long_track).error().text, "track: 3 elements, more than its bound 2");
}

TEST(DbcFrames, AFrameBecomesPhysicalValuesAndPacksBackToTheSameBytes) {
  const Typed body = typed(0);
  const auto codec = DbcFrameCodec::make(body.message, body.type);
  ASSERT_TRUE(codec.ok()) << codec.error().text;
  // Ignition 2 (Run), 12.34 V, raw -8 -> -44 degC, Odometer raw 1000 -> 9900 m, Brake 1.
  const Bytes frame{0x02, 0xD2, 0x04, 0xF8, 0xE8, 0x03, 0x10, 0x00};
  Bytes compact(codec.value().compact_size());
  ASSERT_TRUE(codec.value().to_compact(frame, compact));
  EXPECT_EQ(json_of(body.type, compact),
            R"({"Ignition":"Run","BatteryVoltage":12.34,"AmbientTemp":-44,"Odometer":9900,"Brake":true})");
  Bytes again(8);
  const auto packed = codec.value().to_frame(compact, again, RangePolicy::drop);
  EXPECT_TRUE(packed.sent);
  EXPECT_EQ(packed.out_of_range, 0u);
  EXPECT_EQ(again, frame);
  EXPECT_FALSE(codec.value().to_compact(Bytes(7), compact));  // shorter than the message
}

TEST(DbcFrames, OutOfRangeValuesAreDroppedOrSaturatedAndCounted) {
  const Typed body = typed(0);
  const auto codec = DbcFrameCodec::make(body.message, body.type);
  ASSERT_TRUE(codec.ok());
  Bytes compact(codec.value().compact_size());
  const auto layout = CompactLayout::of_flat_record(body.type);
  ASSERT_TRUE(layout.ok());
  const auto& slots = layout.value().slots();
  ScalarValue volts;
  volts.real = 700.0;  // above 655.35, what 16 bits at 0.01 hold
  write_scalar(ScalarKind::float64, volts, compact.data() + slots[1].offset);
  ScalarValue odometer;
  odometer.integer = 9905;  // (9905 + 100) / 10 = 1000.5: the nearest raw value, 1001 (halves away from zero)
  write_scalar(ScalarKind::int32, odometer, compact.data() + slots[3].offset);
  Bytes frame(8, 0xAA);
  const auto dropped = codec.value().to_frame(compact, frame, RangePolicy::drop);
  EXPECT_FALSE(dropped.sent);
  EXPECT_EQ(dropped.out_of_range, 1u);
  const auto saturated = codec.value().to_frame(compact, frame, RangePolicy::saturate);
  EXPECT_TRUE(saturated.sent);
  EXPECT_EQ(saturated.out_of_range, 1u);
  EXPECT_EQ(frame[1], 0xFF);
  EXPECT_EQ(frame[2], 0xFF);
  EXPECT_EQ(frame[4] | (frame[5] << 8) | ((frame[6] & 0x0F) << 16), 1001);
}

TEST(DbcFrames, OnlyTheSelectedMultiplexedSignalsAreReadAndWritten) {
  const Typed diag = typed(1);
  const auto codec = DbcFrameCodec::make(diag.message, diag.type);
  ASSERT_TRUE(codec.ok());
  Bytes compact(codec.value().compact_size());
  // Mode 2: Pressure (float32 1.5) is carried, Dtc is not.
  const Bytes frame{0x02, 0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x00};
  ASSERT_TRUE(codec.value().to_compact(frame, compact));
  EXPECT_EQ(json_of(diag.type, compact), R"({"Mode":2,"Pressure":1.5})");
  Bytes again(8);
  EXPECT_TRUE(codec.value().to_frame(compact, again, RangePolicy::drop).sent);
  EXPECT_EQ(again, frame);
  const Bytes mode0{0x00, 0x34, 0x12, 0xC0, 0x3F, 0x00, 0x00, 0x00};
  ASSERT_TRUE(codec.value().to_compact(mode0, compact));
  EXPECT_EQ(json_of(diag.type, compact), R"({"Mode":0,"Dtc":4660})");
}

TEST(DbcFrames, TheTypeMustBeTheMessagesOwn) {
  const Typed body = typed(0);
  ChannelType other = body.type;
  other.fields.pop_back();
  const auto codec = DbcFrameCodec::make(body.message, other);
  ASSERT_FALSE(codec.ok());
  EXPECT_NE(codec.error().text.find("is not the type of DBC message BodyStatus"), std::string::npos);
}

TEST(JsonRepresentation, NumbersNamesStringsAndWhatJsonLacks) {
  ChannelType type;
  const auto field = [](std::string name, FieldType t) {
    TypeField f;
    f.name = std::move(name);
    f.type = std::move(t);
    return f;
  };
  FieldType f32;
  f32.scalar = ScalarKind::float32;
  FieldType f64;
  f64.scalar = ScalarKind::float64;
  FieldType state;
  state.kind = FieldType::Kind::enumeration;
  state.scalar = ScalarKind::int8;
  state.values = {{"OFF", 0}, {"ON", 1}};
  FieldType text;
  text.kind = FieldType::Kind::string;
  text.bound = 16;
  type.fields = {field("a", f32), field("b", f64), field("s", state), field("t", text)};
  Bytes event(4 + 8 + 1 + 4);
  ScalarValue v;
  v.real = 0.1;
  write_scalar(ScalarKind::float32, v, event.data());
  v.real = std::numeric_limits<double>::quiet_NaN();
  write_scalar(ScalarKind::float64, v, event.data() + 4);
  event[12] = 7;  // a value the enumeration does not name
  const std::string raw = "q\"\\\x01\xC3\xA9\xFF";
  event[13] = static_cast<std::uint8_t>(raw.size());
  event.insert(event.end(), raw.begin(), raw.end());
  EXPECT_EQ(json_of(type, event),
            "{\"a\":0.10000000149011612,\"b\":null,\"s\":7,\"t\":\"q\\\"\\\\\\u0001\xC3\xA9\\ufffd\"}");
  event[12] = 1;
  EXPECT_NE(json_of(type, event).find("\"s\":\"ON\""), std::string::npos);
  const JsonRepresentation json{ChannelType(type)};
  std::array<char, 8> small{};
  EXPECT_FALSE(json.write(event, small));  // no room: nothing claimed
  EXPECT_FALSE(json.write(Bytes(3), std::span<char>()));
}

}  // namespace
}  // namespace cosmic

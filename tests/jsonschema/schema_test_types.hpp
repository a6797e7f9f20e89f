// Channel types for the JSON Schema tests (cosmic/json_schema.hpp), shared by the unit tests
// (tests/unit/json_schema_test.cpp) and the cases ajv checks (json_schema_cases.cpp), so that what
// the unit tests pin down field by field is what a validator we did not write holds the events to.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/dbc.hpp"
#include "cosmic/dbc_type.hpp"

namespace cosmic::schema_test {

inline FieldType scalar(ScalarKind kind) {
  FieldType t;
  t.scalar = kind;
  return t;
}

inline FieldType enumeration(ScalarKind underlying, std::vector<EnumValue> values) {
  FieldType t;
  t.kind = FieldType::Kind::enumeration;
  t.scalar = underlying;
  t.values = std::move(values);
  return t;
}

inline FieldType bounded(FieldType::Kind kind, std::uint32_t bound, std::optional<FieldType> element = std::nullopt) {
  FieldType t;
  t.kind = kind;
  t.bound = bound;
  if (element) t.element = {std::move(*element)};
  return t;
}

inline FieldType text(std::uint32_t max_bytes) { return bounded(FieldType::Kind::string, max_bytes); }
inline FieldType array(FieldType element, std::uint32_t length) {
  return bounded(FieldType::Kind::array, length, std::move(element));
}
inline FieldType sequence(FieldType element, std::uint32_t max_elements) {
  return bounded(FieldType::Kind::sequence, max_elements, std::move(element));
}

inline FieldType record(std::vector<TypeField> fields) {
  FieldType t;
  t.kind = FieldType::Kind::record;
  t.fields = std::move(fields);
  return t;
}

// Designated initializers name only what a field has: {.unit = "m", .maximum = 40}.
struct FieldExtras {
  std::string unit{};
  std::optional<double> minimum{};
  std::optional<double> maximum{};
  std::optional<FieldPresence> present_when{};
};

inline TypeField field(std::string name, FieldType type, FieldExtras extras = {}) {
  TypeField f;
  f.name = std::move(name);
  f.type = std::move(type);
  f.unit = std::move(extras.unit);
  f.minimum = extras.minimum;
  f.maximum = extras.maximum;
  f.present_when = std::move(extras.present_when);
  return f;
}

inline ChannelType channel_type(std::vector<TypeField> fields) {
  ChannelType type;
  type.fields = std::move(fields);
  return type;
}

// 2^60: a named value and a selector value no double-reading validator can tell from its neighbours.
inline constexpr std::int64_t kBeyondDoubles = std::int64_t{1} << 60;

// Every kind of field: all scalars (units and declared ranges on some), enumerations (one naming a
// value beyond 2^53), a string, arrays (of floats, of arrays), sequences (of integers, of records), a
// nested record, and DBC-like multiplexed fields on a uint8 selector.
inline ChannelType every_kind() {
  using K = ScalarKind;
  return channel_type({
      field("flag", scalar(K::boolean)),
      field("i8", scalar(K::int8)),
      field("i16", scalar(K::int16), {.unit = "degC", .minimum = -40, .maximum = 125}),
      field("i32", scalar(K::int32)),
      field("i64", scalar(K::int64)),
      field("u8", scalar(K::uint8)),
      field("u16", scalar(K::uint16)),
      field("u32", scalar(K::uint32), {.unit = "ms"}),
      field("u64", scalar(K::uint64)),
      field("f32", scalar(K::float32), {.unit = "m/s", .minimum = 0, .maximum = 40}),
      field("f64", scalar(K::float64), {.unit = "m", .minimum = -1.5}),
      field("state", enumeration(K::int8, {{"OFF", -1}, {"IDLE", 0}, {"RUN", 1}})),
      field("gear", enumeration(K::uint64, {{"LOW", 0}, {"HUGE", kBeyondDoubles}})),
      field("label", text(8)),
      field("ranges", array(scalar(K::float32), 4), {.unit = "m", .minimum = 0, .maximum = 10}),
      field("grid", array(array(scalar(K::uint8), 3), 2)),
      field("track", sequence(scalar(K::int16), 3)),
      field("pose",
            record({field("x", scalar(K::float64), {.unit = "m"}), field("y", scalar(K::float64), {.unit = "m"}),
                    field("heading", scalar(K::float32), {.unit = "rad"})})),
      field("path", sequence(record({field("name", text(4)), field("stamp", scalar(K::uint32))}), 2)),
      field("mode", scalar(K::uint8)),
      field("dtc", scalar(K::uint16), {.present_when = FieldPresence{"mode", 0}}),
      field("codes", sequence(scalar(K::uint8), 3), {.present_when = FieldPresence{"mode", 1}}),
      field("pressure", scalar(K::float32), {.unit = "bar", .present_when = FieldPresence{"mode", 2}}),
      field("note", text(6), {.present_when = FieldPresence{"mode", 2}}),
  });
}

// Multiplexed DBC messages: Diagnostics' switch is a plain integer, Status' one has a value table
// (an enumeration selector, written by name).
inline constexpr std::string_view kMultiplexedDbc = R"dbc(BO_ 2566844672 Diagnostics: 8 Gateway
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|65535] "" Ecu
 SG_ Pressure m2 : 8|32@1- (1,0) [0|0] "bar" Ecu
 SG_ Temp m2 : 40|8@1- (0.5,-40) [-40|87.5] "degC" Ecu
BO_ 512 Status: 8 Ecu
 SG_ Page M : 0|2@1+ (1,0) [0|3] "" Gateway
 SG_ Speed m0 : 8|16@1+ (0.01,0) [0|655.35] "km/h" Gateway
 SG_ Doors m1 : 8|4@1+ (1,0) [0|15] "" Gateway
VAL_ 512 Page 0 "Drive" 1 "Body" 2 "Spare" ;
SIG_VALTYPE_ 2566844672 Pressure : 1;
)dbc";

inline ChannelType dbc_message_type(std::string_view message) {
  const DbcFile file = parse_dbc(kMultiplexedDbc);
  for (const DbcMessage& m : file.messages) {
    if (m.name == message) return channel_type_from_dbc(m).type;
  }
  throw std::runtime_error("no DBC message " + std::string(message));
}

// Conditional fields inside records of a sequence, on an enumeration selector, and on an int64
// selector whose value is beyond what doubles tell apart.
inline ChannelType nested_conditional() {
  using K = ScalarKind;
  const FieldType kind = enumeration(K::uint16, {{"POINT", 1}, {"LINE", 2}});
  return channel_type({
      field("items",
            sequence(record({field("kind", kind), field("radius", scalar(K::float32), {.unit = "m"}),
                             field("at", scalar(K::int32), {.present_when = FieldPresence{"kind", 1}}),
                             field("ends", array(scalar(K::int32), 2), {.present_when = FieldPresence{"kind", 2}}),
                             field("spare", text(3), {.present_when = FieldPresence{"kind", 7}})}),
                     3)),
      field("outer", record({field("inner", record({field("deep", record({field("leaf", scalar(K::int8))}))}))})),
      field("key", scalar(K::int64)),
      field("far", scalar(K::uint8), {.present_when = FieldPresence{"key", kBeyondDoubles}}),
      field("near", scalar(K::uint8), {.present_when = FieldPresence{"key", -3}}),
  });
}

// Strings of several bounds, alone and in a sequence.
inline ChannelType strings() {
  return channel_type({field("one", text(1)), field("three", text(3)), field("sixteen", text(16)),
                       field("long", text(64)), field("words", sequence(text(5), 4))});
}

}  // namespace cosmic::schema_test

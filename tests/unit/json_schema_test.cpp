// The JSON Schema of a channel type (cosmic/json_schema.hpp, issue 37): the exact text for a small
// type, and field by field for one with every kind of field. That ajv accepts every event
// JsonRepresentation writes against these schemas is tests/jsonschema (ctest -L jsonschema).
#include "cosmic/json_schema.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "schema_test_types.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::ordered_json;  // keeps the order of properties, which the test checks
using namespace schema_test;

// The text nlohmann writes for `text` (compact, keys in the order given): what json_schema() must
// write to the byte, so an integer written as 40.0 or a key out of place fails.
std::string canonical(const std::string& text) { return Json::parse(text).dump(); }

std::vector<std::string> keys(const Json& object) {
  std::vector<std::string> out;
  for (const auto& item : object.items()) out.push_back(item.key());
  return out;
}

TEST(JsonSchema, TheExactSchemaOfASmallType) {
  const ChannelType type = channel_type({
      field("speed", scalar(ScalarKind::float32), {.unit = "m/s", .minimum = 0, .maximum = 40}),
      field("state", enumeration(ScalarKind::uint8, {{"OFF", 0}, {"ON", 1}})),
      field("name", text(4)),
      field("mode", scalar(ScalarKind::uint8)),
      field("dtc", scalar(ScalarKind::uint16), {.present_when = FieldPresence{"mode", 0}}),
  });
  EXPECT_EQ(json_schema(type, "small"), canonical(R"json({
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "title": "small",
    "type": "object",
    "properties": {
      "speed": {"type": ["number", "null"], "minimum": -3.4028234663852886e+38, "maximum": 3.4028234663852886e+38,
                "description": "unit: m/s; declared range: 0..40 (not enforced: values beyond it are forwarded)"},
      "state": {"anyOf": [{"type": "string", "enum": ["OFF", "ON"]},
                          {"type": "integer", "minimum": 0, "maximum": 255, "not": {"enum": [0, 1]}}]},
      "name": {"type": "string", "maxLength": 4},
      "mode": {"type": "integer", "minimum": 0, "maximum": 255},
      "dtc": {"type": "integer", "minimum": 0, "maximum": 65535, "description": "present only when mode is 0"}
    },
    "required": ["speed", "state", "name", "mode"],
    "additionalProperties": false,
    "allOf": [{"if": {"properties": {"mode": {"const": 0}}},
               "then": {"properties": {"dtc": true}, "required": ["dtc"]},
               "else": {"properties": {"dtc": false}}}]
  })json"));
}

TEST(JsonSchema, AnObjectWithThePropertiesInFieldOrderAndNothingElse) {
  const Json schema = Json::parse(json_schema(every_kind(), "every_kind"));
  EXPECT_EQ(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
  EXPECT_EQ(schema["title"], "every_kind");
  EXPECT_EQ(schema["type"], "object");
  EXPECT_EQ(schema["additionalProperties"], false);
  std::vector<std::string> names;
  for (const TypeField& f : every_kind().fields) names.push_back(f.name);
  EXPECT_EQ(keys(schema["properties"]), names);
  // Every field but the four multiplexed on mode.
  names.resize(names.size() - 4);
  EXPECT_EQ(schema["required"], Json(names));
}

TEST(JsonSchema, ScalarsWithinTheirKindsLimitsExactly) {
  const Json p = Json::parse(json_schema(every_kind(), "every_kind"))["properties"];
  EXPECT_EQ(p["flag"], Json::parse(R"({"type": "boolean"})"));
  EXPECT_EQ(p["i8"], Json::parse(R"({"type": "integer", "minimum": -128, "maximum": 127})"));
  EXPECT_EQ(p["i32"], Json::parse(R"({"type": "integer", "minimum": -2147483648, "maximum": 2147483647})"));
  EXPECT_EQ(p["u8"], Json::parse(R"({"type": "integer", "minimum": 0, "maximum": 255})"));
  EXPECT_EQ(p["u16"], Json::parse(R"({"type": "integer", "minimum": 0, "maximum": 65535})"));
  // 64-bit limits as whole numbers, not doubles (2^63 - 1 as a double is 2^63, beyond int64).
  EXPECT_EQ(p["i64"]["minimum"].get<std::int64_t>(), std::numeric_limits<std::int64_t>::lowest());
  EXPECT_EQ(p["i64"]["maximum"].get<std::int64_t>(), std::numeric_limits<std::int64_t>::max());
  EXPECT_TRUE(p["u64"]["maximum"].is_number_unsigned());
  EXPECT_EQ(p["u64"]["maximum"].get<std::uint64_t>(), std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(p["u32"]["description"], "unit: ms");
  // NaN and infinities are written as null; float32 never beyond its finite limits, float64 anything.
  EXPECT_EQ(p["f32"]["type"], Json::parse(R"(["number", "null"])"));
  EXPECT_EQ(p["f32"]["maximum"].get<double>(), static_cast<double>(std::numeric_limits<float>::max()));
  EXPECT_EQ(p["f32"]["minimum"].get<double>(), -static_cast<double>(std::numeric_limits<float>::max()));
  EXPECT_EQ(p["f64"], Json::parse(R"json({"type": ["number", "null"],
      "description": "unit: m; declared range: -1.5.. (not enforced: values beyond it are forwarded)"})json"));
}

TEST(JsonSchema, ADeclaredRangeIsDescribedNotEnforcedForTheGatewayForwardsValuesBeyondIt) {
  const Json p = Json::parse(json_schema(every_kind(), "every_kind"))["properties"];
  // i16 is declared -40..125, but check_compact accepts any int16 and JsonRepresentation writes it.
  EXPECT_EQ(p["i16"]["minimum"], -32768);
  EXPECT_EQ(p["i16"]["maximum"], 32767);
  EXPECT_EQ(p["i16"]["description"],
            "unit: degC; declared range: -40..125 (not enforced: values beyond it are forwarded)");
  EXPECT_EQ(p["f32"]["description"], "unit: m/s; declared range: 0..40 (not enforced: values beyond it are forwarded)");
}

TEST(JsonSchema, AnEnumerationIsANameOrAnUnnamedNumber) {
  const Json p = Json::parse(json_schema(every_kind(), "every_kind"))["properties"];
  EXPECT_EQ(p["state"], Json::parse(R"({"anyOf": [{"type": "string", "enum": ["OFF", "IDLE", "RUN"]},
      {"type": "integer", "minimum": -128, "maximum": 127, "not": {"enum": [-1, 0, 1]}}]})"));
  // HUGE = 2^60 is not excluded: a double-reading validator takes the unnamed 2^60 + 1 for it.
  EXPECT_EQ(p["gear"]["anyOf"][1]["not"], Json::parse(R"({"enum": [0]})"));
  EXPECT_EQ(p["gear"]["anyOf"][0]["enum"], Json::parse(R"(["LOW", "HUGE"])"));
}

TEST(JsonSchema, StringsArraysSequencesAndRecords) {
  const Json p = Json::parse(json_schema(every_kind(), "every_kind"))["properties"];
  EXPECT_EQ(p["label"], Json::parse(R"({"type": "string", "maxLength": 8})"));
  EXPECT_EQ(p["ranges"]["type"], "array");
  EXPECT_EQ(p["ranges"]["items"], Json::parse(R"({"type": ["number", "null"],
      "minimum": -3.4028234663852886e+38, "maximum": 3.4028234663852886e+38})"));
  EXPECT_EQ(p["ranges"]["minItems"], 4);
  EXPECT_EQ(p["ranges"]["maxItems"], 4);
  EXPECT_EQ(p["ranges"]["description"],
            "unit: m; declared range: 0..10 (not enforced: values beyond it are forwarded)");
  EXPECT_EQ(p["grid"], Json::parse(R"({"type": "array", "items": {"type": "array",
      "items": {"type": "integer", "minimum": 0, "maximum": 255}, "minItems": 3, "maxItems": 3},
      "minItems": 2, "maxItems": 2})"));
  EXPECT_EQ(p["track"], Json::parse(R"({"type": "array", "items": {"type": "integer", "minimum": -32768,
      "maximum": 32767}, "maxItems": 3})"));
  EXPECT_EQ(keys(p["pose"]["properties"]), (std::vector<std::string>{"x", "y", "heading"}));
  EXPECT_EQ(p["pose"]["required"], Json::parse(R"(["x", "y", "heading"])"));
  EXPECT_EQ(p["pose"]["additionalProperties"], false);
  EXPECT_EQ(p["pose"]["properties"]["heading"]["description"], "unit: rad");
  EXPECT_EQ(p["path"]["items"], Json::parse(R"({"type": "object", "properties": {
      "name": {"type": "string", "maxLength": 4},
      "stamp": {"type": "integer", "minimum": 0, "maximum": 4294967295}},
      "required": ["name", "stamp"], "additionalProperties": false})"));
  EXPECT_EQ(p["path"]["maxItems"], 2);
  EXPECT_FALSE(p["path"].contains("minItems"));
}

// The if/then/else that makes `field` present exactly while `selector` is `value`.
Json presence(const std::string& selector, const Json& value, const std::string& field) {
  return Json{{"if", {{"properties", {{selector, {{"const", value}}}}}}},
              {"then", {{"properties", {{field, true}}}, {"required", {field}}}},
              {"else", {{"properties", {{field, false}}}}}};
}

TEST(JsonSchema, MultiplexedFieldsArePresentExactlyWhileTheirSelectorHoldsTheirValue) {
  const Json schema = Json::parse(json_schema(every_kind(), "every_kind"));
  EXPECT_EQ(schema["allOf"], Json::array({presence("mode", 0, "dtc"), presence("mode", 1, "codes"),
                                          presence("mode", 2, "pressure"), presence("mode", 2, "note")}));
  EXPECT_EQ(schema["properties"]["pressure"]["description"], "unit: bar; present only when mode is 2");
  EXPECT_EQ(schema["properties"]["codes"]["description"], "present only when mode is 1");
}

TEST(JsonSchema, ADbcSwitchWithAValueTableSelectsByName) {
  const Json status = Json::parse(json_schema(dbc_message_type("Status"), "status"));
  EXPECT_EQ(status["required"], Json::parse(R"(["Page"])"));
  EXPECT_EQ(status["allOf"], Json::array({presence("Page", "Drive", "Speed"), presence("Page", "Body", "Doors")}));
  EXPECT_EQ(status["properties"]["Speed"]["description"],
            "unit: km/h; declared range: 0..655.35 (not enforced: values beyond it are forwarded); "
            "present only when Page is Drive (0)");
  const Json diagnostics = Json::parse(json_schema(dbc_message_type("Diagnostics"), "diagnostics"));
  EXPECT_EQ(diagnostics["allOf"],
            Json::array({presence("Mode", 0, "Dtc"), presence("Mode", 2, "Pressure"), presence("Mode", 2, "Temp")}));
}

TEST(JsonSchema, ConditionsInsideNestedRecordsAndSelectorValuesBeyondDoubles) {
  const Json p = Json::parse(json_schema(nested_conditional(), "nested"));
  const Json item = p["properties"]["items"]["items"];
  EXPECT_EQ(item["required"], Json::parse(R"(["kind", "radius"])"));
  // A named selector value by its name, an unnamed one by its number.
  EXPECT_EQ(item["allOf"], Json::array({presence("kind", "POINT", "at"), presence("kind", "LINE", "ends"),
                                        presence("kind", 7, "spare")}));
  EXPECT_EQ(item["properties"]["spare"]["description"], "present only when kind is 7");
  // key = 2^60 selects `far`: no rule (2^60 + 1 reads as the same double), so `far` is only optional.
  EXPECT_EQ(p["allOf"], Json::array({presence("key", -3, "near")}));
  EXPECT_EQ(p["required"], Json::parse(R"(["items", "outer", "key"])"));
  EXPECT_EQ(p["properties"]["far"]["description"], "present only when key is 1152921504606846976");
  EXPECT_EQ(p["properties"]["outer"]["properties"]["inner"]["properties"]["deep"]["properties"]["leaf"]["maximum"],
            127);
}

TEST(JsonSchema, TextThatIsNotUtf8BecomesReplacementCharactersAndEveryStringIsEscaped) {
  // A DBC file's unit in Latin-1 ("\xB0" is its degree sign), a title with a quote and a backslash.
  const ChannelType type = channel_type({field("t", scalar(ScalarKind::int8),
                                               {.unit = "\xB0"
                                                        "C \"raw\""})});
  std::string text;
  ASSERT_NO_THROW(text = json_schema(type, "caf\xE9 \"a\\b\""));
  const Json schema = Json::parse(text);
  EXPECT_EQ(schema["title"], "caf\xEF\xBF\xBD \"a\\b\"");
  EXPECT_EQ(schema["properties"]["t"]["description"],
            "unit: \xEF\xBF\xBD"
            "C \"raw\"");
}

}  // namespace
}  // namespace cosmic

// What the JSON event reader (cosmic/json_event_reader.hpp) refuses, each with its reason: the
// field's path and the byte of the text where the fault is, then what is wrong.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/json_event_reader.hpp"
#include "json_event_test_types.hpp"
#include "schema_test_types.hpp"

namespace cosmic {
namespace {

using namespace schema_test;
using namespace json_event_test;

std::string tolerant_refusal(std::string_view part, std::string_view with) {
  return refusal_of(tolerant_type(), tolerant_with(part, with));
}

TEST(JsonEventRefusal, AMissingUnknownOrRepeatedFieldIsRefused) {
  EXPECT_EQ(tolerant_refusal(R"("gear":-3,)", ""), "gear (byte 94): missing");
  EXPECT_EQ(tolerant_refusal(R"("gear":-3,)", R"("gear":-3,"Gear":1,)"), "byte 23: no field is named Gear");
  EXPECT_EQ(tolerant_refusal(R"("gear":-3,)", R"("gear":-3,"gear":1,)"), "gear (byte 23): the field is given twice");
  // Given twice before its turn.
  EXPECT_EQ(tolerant_refusal(R"("speed":1.5,)", R"("gear":-3,"gear":1,"speed":1.5,)"),
            "gear (byte 11): the field is given twice");
  EXPECT_EQ(tolerant_refusal(R"(,"y":2)", ""), "pose.y (byte 97): missing");
  EXPECT_EQ(tolerant_refusal(R"(,"y":2)", ","), "pose (byte 98): expected a field's name");
  EXPECT_EQ(tolerant_refusal(R"("y":2)", R"("y":2,"z":3)"), "pose (byte 104): no field is named z");
}

TEST(JsonEventRefusal, AValueBeyondItsKindIsRefused) {
  EXPECT_EQ(tolerant_refusal("-3", "128"), "gear (byte 20): a number beyond int8");
  EXPECT_EQ(tolerant_refusal("-3", "-129"), "gear (byte 20): a number beyond int8");
  EXPECT_EQ(tolerant_refusal("-3", "-1e3"), "gear (byte 20): a number beyond int8");
  EXPECT_EQ(tolerant_refusal("\"count\":9", "\"count\":-1"), "count (byte 31): a number beyond uint64");
  EXPECT_EQ(tolerant_refusal("\"count\":9", "\"count\":18446744073709551616"),
            "count (byte 31): a number beyond uint64");
  EXPECT_EQ(tolerant_refusal("\"count\":9", "\"count\":1.8446744073709552e19"),
            "count (byte 31): a number beyond uint64");
  EXPECT_EQ(tolerant_refusal("\"count\":9", "\"count\":1e999"), "count (byte 31): a number beyond uint64");
  EXPECT_EQ(tolerant_refusal("1.5", "3.5e38"), "speed (byte 9): a number beyond float32");
  EXPECT_EQ(tolerant_refusal("[0.5,-1]", "[0.5,-1e309]"), "xy[1] (byte 68): a number beyond float64");
  EXPECT_EQ(tolerant_refusal("\"ON\"", "256"), "state (byte 41): a number beyond uint8");
  EXPECT_EQ(tolerant_refusal("-3", "-2.5"), "gear (byte 20): a number that is not a whole number, for int8");
  const ChannelType wide = channel_type({field("i", scalar(ScalarKind::int64))});
  EXPECT_EQ(refusal_of(wide, R"({"i":9223372036854775808})"), "i (byte 5): a number beyond int64");
  EXPECT_EQ(refusal_of(wide, R"({"i":-9.3e18})"), "i (byte 5): a number beyond int64");
  EXPECT_EQ(read_json(wide, R"({"i":-9223372036854775808})").size(), 8u);
}

TEST(JsonEventRefusal, AnUnnamedEnumerationValueByNameIsRefused) {
  EXPECT_EQ(tolerant_refusal("\"ON\"", "\"On\""), "state (byte 41): no value of the enumeration is named On");
  EXPECT_EQ(tolerant_refusal("\"ON\"", "true"),
            "state (byte 41): expected the name or the number of a value, found true or false");
}

TEST(JsonEventRefusal, ATooLongStringOrSequenceAndAnArrayOfAnotherLengthAreRefused) {
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"123456789\""), "name (byte 53): a string longer than its bound of 8 bytes");
  // 8 bytes of UTF-8 in 3 characters fit; 9 do not.
  EXPECT_EQ(uint64_at(read_json(tolerant_type(), tolerant_with("\"hi\"", "\"\\u20ac\\u20ac\\u00e9\""))), 9u);
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"\\u20ac\\u20ac\\u20ac\""),
            "name (byte 53): a string longer than its bound of 8 bytes");
  EXPECT_EQ(tolerant_refusal("[7]", "[7,8,9,10]"), "track (byte 87): more elements than the sequence's bound 3");
  EXPECT_EQ(tolerant_refusal("[0.5,-1]", "[0.5]"), "xy (byte 63): an array of another length than its 2 elements");
  EXPECT_EQ(tolerant_refusal("[0.5,-1]", "[0.5,-1,2]"), "xy (byte 71): more elements than the array's length 2");
  EXPECT_EQ(tolerant_refusal("[0.5,-1]", "[]"), "xy (byte 63): an array of another length than its 2 elements");
}

TEST(JsonEventRefusal, AValueOfTheWrongTypeIsRefused) {
  EXPECT_EQ(tolerant_refusal("1.5", "\"1.5\""), "speed (byte 9): expected a number, found a string");
  EXPECT_EQ(tolerant_refusal("-3", "null"), "gear (byte 20): expected a number, found null");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "7"), "name (byte 53): expected a string, found a number");
  EXPECT_EQ(tolerant_refusal("[7]", "7"), "track (byte 80): expected an array, found a number");
  EXPECT_EQ(tolerant_refusal("{\"x\":1,\"y\":2}", "[1,2]"), "pose (byte 91): expected an object, found an array");
  const ChannelType flag = channel_type({field("on", scalar(ScalarKind::boolean))});
  EXPECT_EQ(refusal_of(flag, R"({"on":1})"), "on (byte 6): expected true or false, found a number");
  EXPECT_EQ(refusal_of(flag, "[]"), "byte 0: expected an object, found an array");
  EXPECT_EQ(refusal_of(flag, ""), "byte 0: expected an object, found no JSON value");
}

TEST(JsonEventRefusal, ConditionalFieldsArePresentExactlyWhenSelected) {
  const ChannelType type = dbc_message_type("Diagnostics");  // Mode; Dtc when 0; Pressure, Temp when 2
  EXPECT_EQ(refusal_of(type, R"({"Mode":2,"Dtc":1})"), "Dtc (byte 10): given while Mode does not select it");
  EXPECT_EQ(refusal_of(type, R"({"Dtc":1,"Mode":2})"), "Dtc (byte 7): given while Mode does not select it");
  // Null is no absence: a selected float's null is NaN.
  EXPECT_EQ(refusal_of(type, R"({"Mode":0,"Dtc":1,"Pressure":null})"),
            "Pressure (byte 18): given while Mode does not select it");
  EXPECT_EQ(refusal_of(type, R"({"Mode":2,"Temp":1})"), "Pressure (byte 18): missing");
}

TEST(JsonEventRefusal, TextThatIsNotJsonIsRefused) {
  EXPECT_EQ(tolerant_refusal("}}", "}} x"), "byte 106: more text after the event");
  EXPECT_EQ(tolerant_refusal("}}", "}}{}"), "byte 105: more text after the event");
  EXPECT_EQ(tolerant_refusal("}}", "}"), "byte 104: expected , or } after a field");
  EXPECT_EQ(tolerant_refusal(",\"gear\"", ",,\"gear\""), "byte 13: expected a field's name");
  EXPECT_EQ(tolerant_refusal("\"gear\":", "\"gear\" "), "byte 20: expected : after a field's name");
  EXPECT_EQ(tolerant_refusal("[0.5,-1]", "[0.5 -1]"), "xy (byte 68): expected , or ] after an element");
  EXPECT_EQ(tolerant_refusal("-3", "03"), "gear (byte 20): a number with a leading zero");
  EXPECT_EQ(tolerant_refusal("-3", "-"), "gear (byte 20): a number without digits");
  EXPECT_EQ(tolerant_refusal("-3", "3."), "gear (byte 20): a number without digits after its point");
  EXPECT_EQ(tolerant_refusal("-3", "3e"), "gear (byte 20): a number without digits in its exponent");
  EXPECT_EQ(tolerant_refusal("-3", "+3"), "gear (byte 20): expected a number, found no JSON value");
  EXPECT_EQ(tolerant_refusal("1.5", "NaN"), "speed (byte 9): expected a number, found no JSON value");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"h\ti\""),
            "name (byte 55): a control character in a string (JSON escapes them)");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"h\xFFi\""), "name (byte 55): a byte that is not part of valid UTF-8");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"h\xC0\xAF\""), "name (byte 55): a byte that is not part of valid UTF-8");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"\\x\""), "name (byte 54): an invalid escape in a string");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"\\u12\""), "name (byte 54): an invalid escape in a string");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"\\ud800x\""), "name (byte 54): an unpaired surrogate escape in a string");
  EXPECT_EQ(tolerant_refusal("\"hi\"", "\"\\udc00\""), "name (byte 54): an unpaired surrogate escape in a string");
  EXPECT_EQ(refusal_of(tolerant_type(), R"({"speed":1.5,"name":"hi)"),
            "name (byte 20): a string without its closing quote");
  EXPECT_EQ(refusal_of(tolerant_type(), R"({"speed":1.5)"), "byte 12: expected , or } after a field");
}

TEST(JsonEventRefusal, NestingDeeperThanTheTypeAllowsIsRefusedWithoutRecursingFar) {
  // A field given before its turn is skipped, whatever it holds, up to kMaxJsonNesting deep.
  const std::string deep(kMaxJsonNesting, '[');
  EXPECT_EQ(tolerant_refusal("\"speed\":1.5,", "\"track\":" + deep + std::string(kMaxJsonNesting, ']') + ","),
            "track (byte " + std::to_string(9 + kMaxJsonNesting - 1) + "): nested deeper than " +
                std::to_string(kMaxJsonNesting) + " arrays and objects");
  const std::string hostile = "{\"pose\":" + std::string(2000, '[');  // within the text bound
  EXPECT_NE(refusal_of(tolerant_type(), hostile).find("nested deeper than"), std::string::npos);
}

TEST(JsonEventRefusal, ATextOverTheBoundIsRefusedBeforeItIsRead) {
  const ChannelType type = tolerant_type();
  const JsonEventReader reader{ChannelType(type)};
  const JsonRepresentation writer{ChannelType(type)};
  EXPECT_EQ(reader.max_text_size(), 2 * writer.max_size() + 4096);
  // Whitespace is read up to the bound, not past it.
  const std::string padded =
      std::string(kTolerantCanonical) + std::string(reader.max_text_size() - kTolerantCanonical.size(), ' ');
  EXPECT_EQ(read_json(type, padded), read_json(type, std::string(kTolerantCanonical)));
  EXPECT_EQ(refusal_of(type, padded + " "), "a text of " + std::to_string(padded.size() + 1) +
                                                " bytes, more than the " + std::to_string(reader.max_text_size()) +
                                                " read for an event of the type");
}

}  // namespace
}  // namespace cosmic

// Typed events read from JSON (cosmic/json_event_reader.hpp): the exact inverse of
// JsonRepresentation::write on many deterministic events of types with every kind of field (write,
// read, write: the same text and the very compact bytes), edge values, and what other producers
// may write differently (order, whitespace, numbers, enumerations by number, escapes).
// Refusals are in json_event_refusal_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/json_event_reader.hpp"
#include "cosmic/json_representation.hpp"
#include "json_event_test_types.hpp"
#include "schema_test_types.hpp"

namespace cosmic {
namespace {

using namespace schema_test;
using namespace json_event_test;

// Canonical events of a type, from a seed: every count within its bound, strings valid UTF-8,
// unselected conditional fields zero, NaN quiet: the events a reader gives back byte for byte.
class CanonicalEventMaker {
 public:
  explicit CanonicalEventMaker(std::uint64_t seed) : random_(seed) {}

  Bytes event(const ChannelType& type) {
    Bytes out;
    record(type.fields, out);
    return out;
  }

 private:
  void record(const std::vector<TypeField>& fields, Bytes& out) {
    std::vector<std::int64_t> values(fields.size(), 0);
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const TypeField& f = fields[i];
      if (f.present_when) {
        std::size_t selector = 0;
        while (fields[selector].name != f.present_when->selector) ++selector;
        if (values[selector] != f.present_when->value) {
          zero(f.type, out);
          continue;
        }
      }
      values[i] = value(f.type, out);
    }
  }

  static void zero(const FieldType& type, Bytes& out) {
    if (const auto size = fixed_compact_size(type)) {
      out.insert(out.end(), *size, 0);
    } else if (type.kind == FieldType::Kind::array) {
      for (std::uint32_t i = 0; i < type.bound; ++i) zero(type.element[0], out);
    } else if (type.kind == FieldType::Kind::record) {
      for (const TypeField& f : type.fields) zero(f.type, out);
    } else {
      out.insert(out.end(), 4, 0);
    }
  }

  std::int64_t value(const FieldType& type, Bytes& out) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
        return scalar(type.scalar, out);
      case FieldType::Kind::enumeration:
        if (pick(3) < 2) {
          const EnumValue& v = type.values[pick(type.values.size())];
          put(type.scalar, v.value, out);
          return v.value;
        }
        return scalar(type.scalar, out);  // most likely a value it does not name
      case FieldType::Kind::string:
        text(type.bound, out);
        return 0;
      case FieldType::Kind::array:
        for (std::uint32_t i = 0; i < type.bound; ++i) value(type.element[0], out);
        return 0;
      case FieldType::Kind::sequence: {
        const auto count = static_cast<std::uint32_t>(pick(type.bound + 1));
        put(ScalarKind::uint32, count, out);
        for (std::uint32_t i = 0; i < count; ++i) value(type.element[0], out);
        return 0;
      }
      case FieldType::Kind::record:
        record(type.fields, out);
        return 0;
    }
    return 0;
  }

  std::int64_t scalar(ScalarKind kind, Bytes& out) {
    const std::size_t bits = 8 * scalar_size(kind);
    ScalarValue v;
    if (kind == ScalarKind::float32 || kind == ScalarKind::float64) {
      const double f64[] = {0.0,
                            -0.0,
                            0.1,
                            -1.5,
                            std::numeric_limits<double>::quiet_NaN(),
                            std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::min(),
                            std::numeric_limits<double>::max(),
                            std::numeric_limits<double>::lowest(),
                            1e300};
      const float f32[] = {0.1f,
                           std::numeric_limits<float>::denorm_min(),
                           std::numeric_limits<float>::min(),
                           std::numeric_limits<float>::max(),
                           std::numeric_limits<float>::lowest(),
                           -0.0f,
                           std::numeric_limits<float>::quiet_NaN(),
                           16777217.0f};
      const std::size_t choice = pick(14);
      if (kind == ScalarKind::float64) {
        v.real = choice < 10 ? f64[choice] : std::uniform_real_distribution<double>(-1e6, 1e6)(random_);
      } else {
        v.real = choice < 8 ? f32[choice] : std::uniform_real_distribution<float>(-1e6f, 1e6f)(random_);
      }
      write(kind, v, out);
      return 0;
    }
    // Small values (selectors select with them), the kind's ends, 2^60, anything.
    const std::uint64_t any = random_();
    const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    const std::uint64_t top = std::uint64_t{1} << (bits - 1);
    const std::uint64_t choices[] = {0, 1, 2, mask, top, top - 1, std::uint64_t{1} << 60, any & mask};
    std::uint64_t bits_value = kind == ScalarKind::boolean ? any & 1 : choices[pick(std::size(choices))] & mask;
    if (is_signed_integer(kind) && bits < 64 && (bits_value & top) != 0) bits_value |= ~mask;  // sign-extend
    v.unsigned_integer = bits_value;
    v.integer = static_cast<std::int64_t>(bits_value);
    write(kind, v, out);
    return is_signed_integer(kind) ? v.integer : static_cast<std::int64_t>(v.unsigned_integer);
  }

  void text(std::uint32_t bound, Bytes& out) {
    static const std::string pieces[] = {"a",
                                         "Z",
                                         "\"",
                                         "\\",
                                         "/",
                                         "\n",
                                         "\x01",
                                         std::string(1, '\0'),
                                         "\xC3\xA9",
                                         "\xE2\x82\xAC",
                                         "\xEF\xBF\xBD",
                                         "\xF0\x9F\x98\x80"};
    std::string s;
    const std::size_t wanted = pick(bound + 1);
    while (s.size() < wanted) {
      const std::string& piece = pieces[pick(std::size(pieces))];
      if (s.size() + piece.size() > bound) break;
      s += piece;
    }
    put(ScalarKind::uint32, static_cast<std::int64_t>(s.size()), out);
    out.insert(out.end(), s.begin(), s.end());
  }

  static void put(ScalarKind kind, std::int64_t value, Bytes& out) {
    ScalarValue v;
    v.integer = value;
    v.unsigned_integer = static_cast<std::uint64_t>(value);
    write(kind, v, out);
  }
  static void write(ScalarKind kind, const ScalarValue& v, Bytes& out) {
    const std::size_t at = out.size();
    out.resize(at + scalar_size(kind));
    write_scalar(kind, v, out.data() + at);
  }
  std::size_t pick(std::size_t n) { return static_cast<std::size_t>(random_() % n); }

  std::mt19937_64 random_;
};

struct NamedType {
  const char* name;
  ChannelType type;
};

std::vector<NamedType> round_trip_types() {
  return {{"every_kind", every_kind()},
          {"nested_conditional", nested_conditional()},
          {"strings", strings()},
          {"Diagnostics", dbc_message_type("Diagnostics")},
          {"Status", dbc_message_type("Status")},
          {"tolerant", tolerant_type()}};
}

TEST(JsonEventReader, WriteReadWriteGivesTheSameTextAndTheVeryEvent) {
  for (const NamedType& t : round_trip_types()) {
    ASSERT_TRUE(check_type(t.type).empty()) << t.name;
    const JsonRepresentation writer{ChannelType(t.type)};
    const JsonEventReader reader{ChannelType(t.type)};
    CanonicalEventMaker maker(0xC05A1C + std::strlen(t.name));
    for (int i = 0; i < 400; ++i) {
      const Bytes event = maker.event(t.type);
      ASSERT_TRUE(check_compact(t.type, event)) << t.name << " event " << i;
      const std::string text = written_json(writer, event);
      Bytes back(reader.max_compact_size());
      const Result<std::size_t> read = reader.read(text, back);
      ASSERT_TRUE(read.ok()) << t.name << " event " << i << ": " << read.error().text << "\n" << text;
      back.resize(read.value());
      EXPECT_EQ(back, event) << t.name << " event " << i << ": " << text;
      EXPECT_EQ(written_json(writer, back), text) << t.name << " event " << i;
      ASSERT_EQ(reader.read_unexplained(text, back), std::optional<std::size_t>(event.size()));
    }
  }
}

TEST(JsonEventReader, AnEventWithTheLongestStringsAndFullestSequencesFitsMaxCompactSize) {
  const ChannelType type = strings();
  const JsonEventReader reader{ChannelType(type)};
  const std::string text = R"({"one":"x","three":"abc","sixteen":"0123456789abcdef","long":")" + std::string(64, 'x') +
                           R"(","words":["12345","12345","12345","12345"]})";
  EXPECT_EQ(read_json(type, text).size(), reader.max_compact_size());
  Bytes short_buffer(reader.max_compact_size() - 1);
  const auto refused = reader.read(text, short_buffer);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().text.find("does not fit the compact buffer"), std::string::npos) << refused.error().text;
}

TEST(JsonEventReader, FieldsInAnyOrderWithWhitespaceReadAsInTheTypesOrder) {
  const ChannelType type = tolerant_type();
  const Bytes canonical = read_json(type, kTolerantCanonical);
  EXPECT_EQ(read_json(type, R"( { "pose" : { "y" : 2 , "x" : 1 } , "track":[7],"name":"hi",
                                  "xy":[0.5,-1],"state":"ON","count":9,"gear":-3,"speed":1.5 } )"),
            canonical);
  EXPECT_EQ(read_json(type, "\t\r\n" + std::string(kTolerantCanonical) + "\n"), canonical);
}

TEST(JsonEventReader, IntegersReadFromIntegralNumbersOfAnySpelling) {
  const ChannelType type = tolerant_type();
  const Bytes canonical = read_json(type, kTolerantCanonical);
  EXPECT_EQ(read_json(type, tolerant_with("\"gear\":-3", "\"gear\":-3.0")), canonical);
  EXPECT_EQ(read_json(type, tolerant_with("\"gear\":-3", "\"gear\":-0.3e1")), canonical);
  EXPECT_EQ(read_json(type, tolerant_with("\"count\":9", "\"count\":9E0")), canonical);
  // -0 is 0 for an unsigned kind; 2^64-1 read exactly as an integer, 1.8e19 as an integral number.
  EXPECT_EQ(uint64_at(read_json(type, tolerant_with("\"count\":9", "\"count\":-0"))), 0u);
  EXPECT_EQ(uint64_at(read_json(type, tolerant_with("\"count\":9", "\"count\":18446744073709551615"))),
            18446744073709551615u);
  EXPECT_EQ(uint64_at(read_json(type, tolerant_with("\"count\":9", "\"count\":1.8e19"))), 18000000000000000000u);
}

TEST(JsonEventReader, FloatsReadFromAnyNumberAndNullAsNaN) {
  const ChannelType type =
      channel_type({field("a", scalar(ScalarKind::float32)), field("b", scalar(ScalarKind::float64))});
  const auto floats = [&](const std::string& text) {
    const Bytes event = read_json(type, text);
    float a = 0;
    double b = 0;
    std::memcpy(&a, event.data(), 4);
    std::memcpy(&b, event.data() + 4, 8);
    return std::pair<float, double>(a, b);
  };
  EXPECT_EQ(floats(R"({"a":3,"b":-7})"), (std::pair<float, double>(3.0f, -7.0)));
  // A float32 rounded to the nearest (0.1 is not one), the largest float32 spelled short.
  EXPECT_EQ(floats(R"({"a":0.1,"b":1e-3})").first, 0.1f);
  EXPECT_EQ(floats(R"({"a":3.4028235e38,"b":0})").first, std::numeric_limits<float>::max());
  // Below the smallest double: 0, with its sign.
  const auto tiny = floats(R"({"a":1e-50,"b":-1e-400})");
  EXPECT_EQ(tiny.first, 0.0f);
  EXPECT_EQ(tiny.second, 0.0);
  EXPECT_TRUE(std::signbit(tiny.second));
  const auto nan = floats(R"({"a":null,"b":null})");
  EXPECT_TRUE(std::isnan(nan.first));
  EXPECT_TRUE(std::isnan(nan.second));
}

TEST(JsonEventReader, AnInfinityIsWrittenAsNullAndComesBackAsNaN) {
  const ChannelType type = channel_type({field("a", scalar(ScalarKind::float64))});
  Bytes event(8);
  const double infinity = std::numeric_limits<double>::infinity();
  std::memcpy(event.data(), &infinity, 8);
  const std::string text = written_json(JsonRepresentation{ChannelType(type)}, event);
  EXPECT_EQ(text, R"({"a":null})");
  double back = 0;
  std::memcpy(&back, read_json(type, text).data(), 8);
  EXPECT_TRUE(std::isnan(back));
}

TEST(JsonEventReader, EnumerationsReadByNameOrByNumberNamedOrNot) {
  const ChannelType type = tolerant_type();
  const Bytes canonical = read_json(type, kTolerantCanonical);
  EXPECT_EQ(read_json(type, tolerant_with("\"state\":\"ON\"", "\"state\":1")), canonical);
  const Bytes unnamed = read_json(type, tolerant_with("\"state\":\"ON\"", "\"state\":200"));
  EXPECT_EQ(written_json(JsonRepresentation{ChannelType(type)}, unnamed),
            tolerant_with("\"state\":\"ON\"", "\"state\":200"));
  EXPECT_EQ(read_json(type, tolerant_with("\"state\":\"ON\"", "\"state\":\"\\u004fN\"")), canonical);
}

TEST(JsonEventReader, StringsDecodeEscapesToUtf8WithinTheirBoundInBytes) {
  const ChannelType type = channel_type({field("s", text(4))});
  const auto string_of = [&](const std::string& json) {
    const Bytes event = read_json(type, json);
    return std::string(event.begin() + 4, event.end());
  };
  EXPECT_EQ(string_of(R"({"s":"\"\\\/\n"})"), "\"\\/\n");
  EXPECT_EQ(string_of(R"({"s":"\b\f\r\t"})"), "\b\f\r\t");
  EXPECT_EQ(string_of(R"({"s":"\u00e9\u0000"})"), "\xC3\xA9" + std::string(1, '\0'));
  EXPECT_EQ(string_of(R"({"s":"\ud83d\ude00"})"), "\xF0\x9F\x98\x80");  // a surrogate pair: 4 bytes
  EXPECT_EQ(string_of("{\"s\":\"\xF0\x9F\x98\x80\"}"), "\xF0\x9F\x98\x80");
  // U+FFFD, which write() gives an invalid byte, takes three bytes: one fits, two do not.
  EXPECT_EQ(string_of(R"({"s":"\ufffd"})"), "\xEF\xBF\xBD");
  Bytes room(64);
  EXPECT_FALSE(JsonEventReader(ChannelType(type)).read(R"({"s":"\ufffd\ufffd"})", room).ok());
}

TEST(JsonEventReader, AnInvalidByteWrittenAsReplacementReadsBackAsU_FFFD) {
  const ChannelType type = channel_type({field("s", text(8))});
  const Bytes event{2, 0, 0, 0, 'a', 0xFF};
  const std::string text = written_json(JsonRepresentation{ChannelType(type)}, event);
  EXPECT_EQ(text, R"({"s":"a\ufffd"})");
  EXPECT_EQ(read_json(type, text), (Bytes{4, 0, 0, 0, 'a', 0xEF, 0xBF, 0xBD}));
}

TEST(JsonEventReader, AConditionalFieldIsReadExactlyWhenSelectedAndIsZeroOtherwise) {
  const ChannelType type = dbc_message_type("Diagnostics");  // Mode; Dtc when 0; Pressure, Temp when 2
  const Bytes two = read_json(type, R"({"Pressure":1.5,"Mode":2,"Temp":-3.5})");
  EXPECT_EQ(written_json(JsonRepresentation{ChannelType(type)}, two), R"({"Mode":2,"Pressure":1.5,"Temp":-3.5})");
  const Bytes zero = read_json(type, R"({"Mode":0,"Dtc":4660})");
  EXPECT_EQ(written_json(JsonRepresentation{ChannelType(type)}, zero), R"({"Mode":0,"Dtc":4660})");
  const Bytes other = read_json(type, R"({"Mode":7})");
  const Bytes expected = [&] {
    Bytes b(other.size(), 0);
    b[0] = 7;
    return b;
  }();
  EXPECT_EQ(other, expected);  // every unselected field's bits zero
}

TEST(JsonEventReader, AConditionalFieldInsideRecordsOfASequenceFollowsItsOwnSelector) {
  const ChannelType type = nested_conditional();
  const std::string text =
      R"({"items":[{"kind":"LINE","radius":1,"ends":[1,2]},{"at":-4,"kind":"POINT","radius":0.5}],)"
      R"("outer":{"inner":{"deep":{"leaf":-8}}},"key":1152921504606846976,"far":3})";
  const Bytes event = read_json(type, text);
  EXPECT_EQ(written_json(JsonRepresentation{ChannelType(type)}, event),
            R"({"items":[{"kind":"LINE","radius":1,"ends":[1,2]},{"kind":"POINT","radius":0.5,"at":-4}],)"
            R"("outer":{"inner":{"deep":{"leaf":-8}}},"key":1152921504606846976,"far":3})");
}

}  // namespace
}  // namespace cosmic

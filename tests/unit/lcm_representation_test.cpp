// A typed channel's LCM messages in the struct's own encoding (cosmic/lcm_representation.hpp):
// messages and events written out byte by byte here, each way; round trips; every way a message or
// an event is refused; types the representation refuses. tests/integration/lcm_types holds it
// against lcm-gen's generated C and Python code.
#include "cosmic/lcm_representation.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"

namespace cosmic::lcm_representation_test {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::string_view kLcmEncodingTypes = R"lcm(package exlcm;
struct point_t { int16_t a; string label; }
struct example_t
{
    int64_t timestamp;
    int8_t  small;
    boolean flag;
    string  name;
    int16_t fixed[3];
    int32_t num;
    float   ranges[num];
    point_t points[2];
    int8_t  rows;
    byte    grid[rows][3];
    double  columns[2][num];
}
struct inner_t { int8_t n; int16_t v[n]; }
struct outer_t { int8_t n; inner_t items[2]; int16_t w[n]; }
struct numbers_t { int64_t a; int8_t b; int16_t c; boolean f; byte u; float x; double y; }
)lcm";

const LcmTypeFile& lcm_encoding_file() {
  static const LcmTypeFile file = parse_lcm_types(kLcmEncodingTypes);
  return file;
}

ChannelType lcm_encoding_type(std::string_view name, const std::map<std::string, std::uint32_t>& max_length = {}) {
  const LcmChannelType typed = lcm_channel_type(lcm_encoding_file(), *lcm_encoding_file().find(name), max_length);
  EXPECT_TRUE(typed.ok()) << typed.errors.front().message;
  return typed.type;
}

LcmRepresentation lcm_encoding_of(std::string_view name, const ChannelType& type) {
  auto made = LcmRepresentation::make(lcm_encoding_file(), *lcm_encoding_file().find(name), type);
  EXPECT_TRUE(made.ok()) << made.error().text;
  return std::move(made).value();
}

const std::map<std::string, std::uint32_t> kExampleBounds{{"ranges", 4}, {"grid", 3}, {"columns", 4}};

LcmRepresentation example_encoding() {
  return lcm_encoding_of("exlcm.example_t", lcm_encoding_type("exlcm.example_t", kExampleBounds));
}

// The fingerprint, big-endian, then `body`.
Bytes lcm_message(const LcmRepresentation& lcm, const Bytes& body) {
  Bytes out;
  for (int shift = 56; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(lcm.fingerprint() >> shift));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

Bytes lcm_to_compact(const LcmRepresentation& lcm, const Bytes& wire,
                     ConversionFault expected = ConversionFault::none) {
  Bytes compact(lcm.max_compact_size());
  const Conversion c = lcm.to_compact(wire, compact);
  EXPECT_EQ(c.fault, expected);
  compact.resize(c.size);
  return compact;
}

Bytes lcm_from_compact(const LcmRepresentation& lcm, const Bytes& compact,
                       ConversionFault expected = ConversionFault::none) {
  Bytes wire(lcm.max_wire_size());
  const Conversion c = lcm.from_compact(compact, wire);
  EXPECT_EQ(c.fault, expected);
  wire.resize(c.size);
  return wire;
}

// example_t: timestamp 0x0102030405060708, small -2, flag true, name "hi", fixed {1, -1, 0x0203},
// num 2, ranges {1.5f, -2.0f}, points {{7, "a"}, {-8, ""}}, rows 1, grid {{9, 10, 11}},
// columns {{0.5, 1.0}, {-0.25, 2.0}}.
const Bytes kExampleBody{
    0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,  // timestamp
    0xFE,                                            // small: an int8 right after an int64
    0x01,                                            // flag
    0x00, 0x00, 0x00, 0x03, 'h',  'i',  0x00,        // name: length with its NUL
    0x00, 0x01, 0xFF, 0xFF, 0x02, 0x03,              // fixed[3]
    0x00, 0x00, 0x00, 0x02,                          // num
    0x3F, 0xC0, 0x00, 0x00, 0xC0, 0x00, 0x00, 0x00,  // ranges[num]: no length of their own
    0x00, 0x07, 0x00, 0x00, 0x00, 0x02, 'a',  0x00,  // points[0], no fingerprint
    0xFF, 0xF8, 0x00, 0x00, 0x00, 0x01, 0x00,        // points[1]: an empty string
    0x01,                                            // rows
    0x09, 0x0A, 0x0B,                                // grid[rows][3]
    0x3F, 0xE0, 0,    0,    0,    0,    0,    0,    0x3F, 0xF0, 0, 0, 0, 0, 0, 0,  // columns[0][num]
    0xBF, 0xD0, 0,    0,    0,    0,    0,    0,    0x40, 0x00, 0, 0, 0, 0, 0, 0,  // columns[1][num]
};
const Bytes kExampleCompact{
    0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01,  // timestamp
    0xFE,                                            // small
    0x01,                                            // flag
    0x02, 0x00, 0x00, 0x00, 'h',  'i',               // name: count without a NUL
    0x01, 0x00, 0xFF, 0xFF, 0x03, 0x02,              // fixed
    0x02, 0x00, 0x00, 0x00,                          // num
    0x02, 0x00, 0x00, 0x00,                          // ranges: a count of their own
    0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x00, 0xC0,  // ...
    0x07, 0x00, 0x01, 0x00, 0x00, 0x00, 'a',         // points[0]
    0xF8, 0xFF, 0x00, 0x00, 0x00, 0x00,              // points[1]
    0x01,                                            // rows
    0x01, 0x00, 0x00, 0x00, 0x09, 0x0A, 0x0B,        // grid
    0x02, 0x00, 0x00, 0x00, 0,    0,    0,    0,    0, 0, 0xE0, 0x3F, 0, 0, 0, 0, 0, 0, 0xF0, 0x3F,  // columns[0]
    0x02, 0x00, 0x00, 0x00, 0,    0,    0,    0,    0, 0, 0xD0, 0xBF, 0, 0, 0, 0, 0, 0, 0x00, 0x40,  // columns[1]
};
// Where example_t's count members and strings are in kExampleBody (after the fingerprint).
constexpr std::size_t kNameLengthAt = 10, kNameNulAt = 16, kNumAt = 23, kRowsAt = 50;

TEST(LcmRepresentation, ScalarsInEveryWidthBigEndianOnTheWire) {
  const LcmRepresentation lcm = lcm_encoding_of("exlcm.numbers_t", lcm_encoding_type("exlcm.numbers_t"));
  const Bytes body{0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,   // a
                   0x80,                                             // b = -128, after an int64
                   0x12, 0x34,                                       // c
                   0x00,                                             // f
                   0xAB,                                             // u
                   0x3F, 0xC0, 0x00, 0x00,                           // x = 1.5f
                   0x40, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};  // y = 2.5
  const Bytes compact{0x08, 0x07, 0x06, 0x05, 0x04, 0x03, 0x02, 0x01, 0x80, 0x34, 0x12, 0x00, 0xAB,
                      0x00, 0x00, 0xC0, 0x3F, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x04, 0x40};
  EXPECT_EQ(lcm.max_wire_size(), 8u + 25u);
  EXPECT_EQ(lcm.max_compact_size(), 25u);
  EXPECT_EQ(lcm_to_compact(lcm, lcm_message(lcm, body)), compact);
  EXPECT_EQ(lcm_from_compact(lcm, compact), lcm_message(lcm, body));
}

TEST(LcmRepresentation, StringsArraysSequencesNestedStructsAndTwoDimensions) {
  ASSERT_EQ(kExampleBody[kNumAt + 3], 2);
  ASSERT_EQ(kExampleBody[kRowsAt], 1);
  const LcmRepresentation lcm = example_encoding();
  EXPECT_EQ(lcm.describe(), "LCM exlcm.example_t");
  EXPECT_EQ(lcm.fingerprint(), lcm_fingerprint(lcm_encoding_file(), *lcm_encoding_file().find("exlcm.example_t")));
  const ChannelType type = lcm_encoding_type("exlcm.example_t", kExampleBounds);
  const Bytes compact = lcm_to_compact(lcm, lcm_message(lcm, kExampleBody));
  EXPECT_EQ(compact, kExampleCompact);
  EXPECT_TRUE(check_compact(type, compact).ok());
  EXPECT_EQ(lcm_from_compact(lcm, kExampleCompact), lcm_message(lcm, kExampleBody));
  EXPECT_EQ(lcm.max_compact_size(), max_compact_size(type));
  // 8 + 8 + 1 + 1 + (4 + 65536 + 1) + 3 * 2 + 4 + 4 * 4 + 2 * (2 + 4 + 65536 + 1) + 1 + 3 * 3 + 2 * 4 * 8
  EXPECT_EQ(lcm.max_wire_size(), 196'745u);
}

TEST(LcmRepresentation, CountMembersOfNestedStructsInArrays) {
  const LcmRepresentation lcm = lcm_encoding_of("exlcm.outer_t", lcm_encoding_type("exlcm.outer_t"));
  // n 1; items {{n 2, v {1, 2}}, {n 0}}; w {3}: the inner n changes between the items, the outer
  // one still counts w.
  const Bytes body{0x01, 0x02, 0x00, 0x01, 0x00, 0x02, 0x00, 0x00, 0x03};
  const Bytes compact{0x01, 0x02, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00, 0x02, 0x00, 0x00,
                      0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x03, 0x00};
  EXPECT_EQ(lcm_to_compact(lcm, lcm_message(lcm, body)), compact);
  EXPECT_EQ(lcm_from_compact(lcm, compact), lcm_message(lcm, body));
}

TEST(LcmRepresentation, RoundTripsOfMessagesOfEveryLength) {
  const LcmRepresentation lcm = example_encoding();
  const ChannelType type = lcm_encoding_type("exlcm.example_t", kExampleBounds);
  // num 0, rows 0: empty sequences; then num 4 and rows 3 at their bounds, a long name.
  Bytes body{1, 2, 3, 4, 5, 6, 7, 8, 0x7F, 0, 0, 0, 0, 1, 0, 0, 1, 0, 2, 0, 3, 0, 0, 0, 0};
  const Bytes points{0x00, 0x07, 0x00, 0x00, 0x00, 0x02, 'a', 0x00, 0xFF, 0xF8, 0x00, 0x00, 0x00, 0x01, 0x00};
  body.insert(body.end(), points.begin(), points.end());
  body.push_back(0);  // rows
  const Bytes empty = lcm_message(lcm, body);
  const Bytes event = lcm_to_compact(lcm, empty);
  EXPECT_TRUE(check_compact(type, event).ok());
  EXPECT_EQ(lcm_from_compact(lcm, event), empty);

  Bytes full = lcm_message(lcm, {1, 2, 3, 4, 5, 6, 7, 8, 0x80, 1, 0, 0, 0, 41});
  for (int i = 0; i < 40; ++i) full.push_back(static_cast<std::uint8_t>('A' + i % 26));
  full.insert(full.end(), {0, 0, 1, 0, 2, 0, 3, 0, 0, 0, 4});
  for (int i = 0; i < 16; ++i) full.push_back(static_cast<std::uint8_t>(i * 13));  // ranges[4]
  full.insert(full.end(), points.begin(), points.end());
  full.push_back(3);
  for (int i = 0; i < 9; ++i) full.push_back(static_cast<std::uint8_t>(200 + i));  // grid[3][3]
  for (int i = 0; i < 64; ++i) full.push_back(static_cast<std::uint8_t>(i * 7));   // columns[2][4]
  const Bytes full_event = lcm_to_compact(lcm, full);
  EXPECT_TRUE(check_compact(type, full_event).ok());
  EXPECT_EQ(lcm_from_compact(lcm, full_event), full);
}

TEST(LcmRepresentation, MessagesCutShortOrTooLongOrOfAnotherTypeAreMalformed) {
  const LcmRepresentation lcm = example_encoding();
  const Bytes whole = lcm_message(lcm, kExampleBody);
  for (std::size_t size = 0; size < whole.size(); ++size) {
    lcm_to_compact(lcm, Bytes(whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(size)),
                   ConversionFault::malformed);
  }
  Bytes longer = whole;
  longer.push_back(0);
  lcm_to_compact(lcm, longer, ConversionFault::malformed);
  Bytes other = whole;
  other[7] ^= 1;  // the fingerprint's last byte
  lcm_to_compact(lcm, other, ConversionFault::malformed);
}

TEST(LcmRepresentation, StringsNeedALengthOfAtLeastOneANulAndAtMostTheirBound) {
  ChannelType type = lcm_encoding_type("exlcm.example_t", kExampleBounds);
  type.fields[3].type.bound = 3;  // name: at most 3 bytes
  const LcmRepresentation lcm = lcm_encoding_of("exlcm.example_t", type);
  const auto with = [&](std::size_t at, std::uint8_t value) {
    Bytes body = kExampleBody;
    body[at] = value;
    return lcm_message(lcm, body);
  };
  EXPECT_EQ(lcm_to_compact(lcm, with(kNameNulAt, 0)), kExampleCompact);
  lcm_to_compact(lcm, with(kNameNulAt, 'x'), ConversionFault::malformed);  // no NUL at its end
  // A length of 0 (no room for the NUL), a negative one.
  lcm_to_compact(lcm, with(kNameLengthAt + 3, 0), ConversionFault::malformed);
  lcm_to_compact(lcm, with(kNameLengthAt, 0xFF), ConversionFault::malformed);
  // "hi!" is at the bound of 3 (length 4); "hi!?" is over it (length 5).
  Bytes body(kExampleBody.begin(), kExampleBody.begin() + kNameLengthAt);
  const Bytes rest(kExampleBody.begin() + kNameNulAt + 1, kExampleBody.end());
  Bytes at_bound = body;
  at_bound.insert(at_bound.end(), {0, 0, 0, 4, 'h', 'i', '!', 0});
  at_bound.insert(at_bound.end(), rest.begin(), rest.end());
  const Bytes event = lcm_to_compact(lcm, lcm_message(lcm, at_bound));
  EXPECT_EQ(lcm_from_compact(lcm, event), lcm_message(lcm, at_bound));
  Bytes over = body;
  over.insert(over.end(), {0, 0, 0, 5, 'h', 'i', '!', '?', 0});
  over.insert(over.end(), rest.begin(), rest.end());
  lcm_to_compact(lcm, lcm_message(lcm, over), ConversionFault::malformed);
}

TEST(LcmRepresentation, CountMembersNegativeOrOverTheirBoundAreMalformed) {
  const LcmRepresentation lcm = example_encoding();
  Bytes negative = kExampleBody;
  negative[kNumAt] = 0xFF;  // num = 0xFF000002: negative
  lcm_to_compact(lcm, lcm_message(lcm, negative), ConversionFault::malformed);
  Bytes minus_one = kExampleBody;
  minus_one[kRowsAt] = 0xFF;  // rows = -1
  lcm_to_compact(lcm, lcm_message(lcm, minus_one), ConversionFault::malformed);
  // rows 4 over grid's bound of 3 (the message has the bytes for it).
  Bytes over = kExampleBody;
  over[kRowsAt] = 4;
  over.insert(over.begin() + kRowsAt + 1, {1, 2, 3, 4, 5, 6, 7, 8, 9});
  lcm_to_compact(lcm, lcm_message(lcm, over), ConversionFault::malformed);
  // A nested struct's count member: items[0].n = -2.
  const LcmRepresentation outer = lcm_encoding_of("exlcm.outer_t", lcm_encoding_type("exlcm.outer_t"));
  lcm_to_compact(outer, lcm_message(outer, {0x01, 0xFE, 0x00, 0x00, 0x00, 0x03}), ConversionFault::malformed);
}

TEST(LcmRepresentation, AnyNonzeroBooleanIsTrueAndBecomesOne) {
  const LcmRepresentation lcm = example_encoding();
  Bytes body = kExampleBody;
  body[9] = 0x80;  // flag: lcm-gen's decoders read an int8 and take any value but 0 as true
  const Bytes event = lcm_to_compact(lcm, lcm_message(lcm, body));
  EXPECT_EQ(event, kExampleCompact);
  EXPECT_EQ(lcm_from_compact(lcm, event), lcm_message(lcm, kExampleBody));
}

TEST(LcmRepresentation, EventsWhoseSequenceCountsAreNotTheirCountMembersAreMalformed) {
  const LcmRepresentation lcm = example_encoding();
  const ChannelType type = lcm_encoding_type("exlcm.example_t", kExampleBounds);
  // num says 2, ranges holds 1 (the event is sound in the compact layout: check_compact accepts it).
  Bytes fewer = kExampleCompact;
  fewer[26] = 1;
  fewer.erase(fewer.begin() + 34, fewer.begin() + 38);
  ASSERT_TRUE(check_compact(type, fewer).ok());
  lcm_from_compact(lcm, fewer, ConversionFault::malformed);
  // columns[1] holds 1 where num says 2: the second sequence of a 2-D array.
  Bytes inner = kExampleCompact;
  inner[inner.size() - 20] = 1;
  inner.resize(inner.size() - 8);
  ASSERT_TRUE(check_compact(type, inner).ok());
  lcm_from_compact(lcm, inner, ConversionFault::malformed);
  // A negative count member with empty sequences: LCM's readers could not read it back.
  const LcmRepresentation outer = lcm_encoding_of("exlcm.outer_t", lcm_encoding_type("exlcm.outer_t"));
  const Bytes negative{0xFF, 0x00, 0, 0, 0, 0, 0x00, 0, 0, 0, 0, 0, 0, 0, 0};
  ASSERT_TRUE(check_compact(lcm_encoding_type("exlcm.outer_t"), negative).ok());
  lcm_from_compact(outer, negative, ConversionFault::malformed);
}

TEST(LcmRepresentation, EventsCutShortOrTooLongAreMalformed) {
  const LcmRepresentation lcm = example_encoding();
  for (std::size_t size = 0; size < kExampleCompact.size(); ++size) {
    lcm_from_compact(lcm, Bytes(kExampleCompact.begin(), kExampleCompact.begin() + static_cast<std::ptrdiff_t>(size)),
                     ConversionFault::malformed);
  }
  Bytes longer = kExampleCompact;
  longer.push_back(0);
  lcm_from_compact(lcm, longer, ConversionFault::malformed);
}

TEST(LcmRepresentation, BuffersBelowTheBoundsAreTooSmall) {
  const LcmRepresentation lcm = example_encoding();
  Bytes wire(lcm.max_wire_size() - 1);
  EXPECT_EQ(lcm.from_compact(kExampleCompact, wire).fault, ConversionFault::too_small);
  Bytes compact(lcm.max_compact_size() - 1);
  EXPECT_EQ(lcm.to_compact(lcm_message(lcm, kExampleBody), compact).fault, ConversionFault::too_small);
}

std::string lcm_refusal(std::string_view name, const ChannelType& type) {
  const auto made = LcmRepresentation::make(lcm_encoding_file(), *lcm_encoding_file().find(name), type);
  return made.ok() ? "made" : made.error().text;
}

TEST(LcmRepresentation, TypesOfAnotherShapeAreRefused) {
  const ChannelType example = lcm_encoding_type("exlcm.example_t", kExampleBounds);
  ChannelType renamed = example;
  renamed.fields[1].name = "tiny";
  EXPECT_EQ(lcm_refusal("exlcm.example_t", renamed), "LCM exlcm.example_t.small: the type's field here is tiny");
  ChannelType wider = example;
  wider.fields[1].type.scalar = ScalarKind::int16;
  EXPECT_EQ(lcm_refusal("exlcm.example_t", wider),
            "LCM exlcm.example_t.small: int8_t in the struct, int16 in the type");
  ChannelType longer = example;
  longer.fields[4].type.bound = 4;
  EXPECT_EQ(lcm_refusal("exlcm.example_t", longer),
            "LCM exlcm.example_t.fixed: dimension [3] of the struct's member, int16[4] in the type");
  ChannelType fixed = example;
  fixed.fields[6].type.kind = FieldType::Kind::array;
  EXPECT_EQ(lcm_refusal("exlcm.example_t", fixed),
            "LCM exlcm.example_t.ranges: dimension [num] of the struct's member, float32[4] in the type");
  ChannelType nested = example;
  nested.fields[7].type.element[0].fields[1].type.kind = FieldType::Kind::scalar;
  nested.fields[7].type.element[0].fields[1].type.scalar = ScalarKind::int8;
  nested.fields[7].type.element[0].fields[1].type.bound = 0;
  EXPECT_EQ(lcm_refusal("exlcm.example_t", nested),
            "LCM exlcm.example_t.points.label: string in the struct, int8 in the type");
  ChannelType fewer = example;
  fewer.fields.pop_back();
  EXPECT_EQ(lcm_refusal("exlcm.example_t", fewer),
            "LCM exlcm.example_t: the type has 10 fields, struct exlcm.example_t 11 members");
  ChannelType conditional = example;
  conditional.fields[2].present_when = FieldPresence{"small", 1};
  EXPECT_EQ(lcm_refusal("exlcm.example_t", conditional),
            "LCM exlcm.example_t.flag: a conditional field, which LCM has not");
  ChannelType unsound = example;
  unsound.fields[3].type.bound = 0;
  EXPECT_EQ(lcm_refusal("exlcm.example_t", unsound), "LCM exlcm.example_t: name: bound 0 is not 1..65536");
}

TEST(LcmRepresentation, StructsItCannotEncodeAreRefused) {
  // The parser refuses a variable dimension without an earlier integer count; a struct made by
  // hand is refused here all the same.
  LcmTypeFile file;
  LcmStruct s;
  s.name = "t";
  s.members = {LcmMember{"v", "double", {LcmDimension{true, "n"}}, 0, 0}, LcmMember{"n", "int32_t", {}, 0, 0}};
  file.structs = {s};
  ChannelType type;
  FieldType sequence;
  sequence.kind = FieldType::Kind::sequence;
  sequence.bound = 4;
  sequence.element = {FieldType{}};
  type.fields = {TypeField{"v", sequence, "", {}, {}, {}},
                 TypeField{"n", FieldType{FieldType::Kind::scalar, ScalarKind::int32, {}, 0, {}, {}}, "", {}, {}, {}}};
  const auto made = LcmRepresentation::make(file, file.structs[0], type);
  ASSERT_FALSE(made.ok());
  EXPECT_EQ(made.error().text, "LCM t.v: its size n is not an integer member declared before it");
  // A nested struct missing from the file.
  const LcmTypeFile missing = parse_lcm_types("struct a_t { other.b_t b; }");
  EXPECT_EQ(LcmRepresentation::make(missing, missing.structs[0], ChannelType{}).error().text,
            "LCM struct a_t nests a struct missing from its file or itself");
  // 40000 strings of up to 65536 bytes: more than lcm-gen's C code can count.
  const LcmTypeFile big = parse_lcm_types("struct big_t { string s[40000]; }");
  const LcmChannelType big_type = lcm_channel_type(big, big.structs[0]);
  ASSERT_TRUE(big_type.ok());
  EXPECT_EQ(LcmRepresentation::make(big, big.structs[0], big_type.type).error().text,
            "LCM big_t: its messages could be longer than 2^31 - 1 bytes (bound its strings and arrays)");
}

}  // namespace
}  // namespace cosmic::lcm_representation_test

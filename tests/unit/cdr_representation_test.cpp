// A typed channel's samples in extended CDR (cosmic/cdr_representation.hpp): the bytes of XCDR1 and
// XCDR2 (final and appendable) computed by hand from XTypes 1.3 7.4.3 for the ROS 2 Twist, an 8-byte
// value after a 1-byte one, strings, sequences of structs, arrays and enumerations; big-endian
// input; XCDR1 read and XCDR2 written (transcoding); every way a sample is malformed.
#include <gtest/gtest.h>

#include <bit>
#include <string>
#include <vector>

#include "cosmic/cdr_representation.hpp"
#include "cosmic/compact_layout.hpp"

namespace cosmic {
// Its own namespace: unity builds merge test files, whose anonymous helpers must not clash.
namespace cdr_test {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Bytes by hand, little-endian unless told otherwise.
class ByteText {
 public:
  explicit ByteText(bool big_endian = false) : big_endian_(big_endian) {}
  ByteText& raw(std::initializer_list<std::uint8_t> bytes) {
    bytes_.insert(bytes_.end(), bytes);
    return *this;
  }
  ByteText& zeros(std::size_t n) {
    bytes_.insert(bytes_.end(), n, 0);
    return *this;
  }
  ByteText& u8(std::uint8_t v) { return raw({v}); }
  ByteText& u16(std::uint16_t v) { return number(v, 2); }
  ByteText& u32(std::uint32_t v) { return number(v, 4); }
  ByteText& f64(double v) { return number(std::bit_cast<std::uint64_t>(v), 8); }
  ByteText& text(const std::string& s) {
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  Bytes bytes() const { return bytes_; }

 private:
  ByteText& number(std::uint64_t v, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i)
      bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * (big_endian_ ? size - 1 - i : i))));
    return *this;
  }
  bool big_endian_;
  Bytes bytes_;
};

FieldType cdr_scalar(ScalarKind kind) {
  FieldType t;
  t.kind = FieldType::Kind::scalar;
  t.scalar = kind;
  return t;
}
FieldType cdr_string(std::uint32_t bound) {
  FieldType t;
  t.kind = FieldType::Kind::string;
  t.bound = bound;
  return t;
}
FieldType cdr_collection(FieldType::Kind kind, FieldType element, std::uint32_t bound) {
  FieldType t;
  t.kind = kind;
  t.bound = bound;
  t.element = {std::move(element)};
  return t;
}
FieldType cdr_enum(ScalarKind underlying) {
  FieldType t;
  t.kind = FieldType::Kind::enumeration;
  t.scalar = underlying;
  t.values = {{"OFF", 0}, {"ON", 1}};
  return t;
}
FieldType cdr_record(std::vector<TypeField> fields) {
  FieldType t;
  t.kind = FieldType::Kind::record;
  t.fields = std::move(fields);
  return t;
}
TypeField cdr_field(std::string name, FieldType type) {
  TypeField f;
  f.name = std::move(name);
  f.type = std::move(type);
  return f;
}
ChannelType cdr_type(std::vector<TypeField> fields) { return ChannelType{std::move(fields), std::nullopt}; }

CdrRepresentation cdr_make(const ChannelType& type, DdsRepresentation version,
                           CdrExtensibility extensibility = CdrExtensibility::final_type) {
  auto made = CdrRepresentation::make(type, version, extensibility);
  EXPECT_TRUE(made.ok()) << made.error().text;
  return std::move(made).value();
}

// The sample from_compact writes, or empty when it refuses.
Bytes cdr_write(const CdrRepresentation& cdr, const Bytes& compact) {
  Bytes wire(cdr.max_wire_size());
  const Conversion c = cdr.from_compact(compact, wire);
  if (!c.ok()) return {};
  wire.resize(c.size);
  return wire;
}

// The event to_compact reads, or the fault.
struct CdrRead {
  Bytes compact;
  ConversionFault fault = ConversionFault::none;
};
CdrRead cdr_read(const CdrRepresentation& cdr, const Bytes& wire) {
  Bytes compact(cdr.max_compact_size());
  const Conversion c = cdr.to_compact(wire, compact);
  compact.resize(c.size);
  return CdrRead{compact, c.fault};
}

ChannelType twist_type() {
  const auto vector3 = [] {
    return cdr_record({cdr_field("x", cdr_scalar(ScalarKind::float64)), cdr_field("y", cdr_scalar(ScalarKind::float64)),
                       cdr_field("z", cdr_scalar(ScalarKind::float64))});
  };
  return cdr_type({cdr_field("linear", vector3()), cdr_field("angular", vector3())});
}

Bytes twist_doubles() { return ByteText().f64(1).f64(1.5).f64(-1).f64(0.25).f64(-0.125).f64(1001).bytes(); }

TEST(CdrRepresentation, TwistInXcdr1IsTheHeaderAndSixDoubles) {
  const CdrRepresentation cdr = cdr_make(twist_type(), DdsRepresentation::xcdr1);
  Bytes expected = ByteText().raw({0x00, 0x01, 0x00, 0x00}).bytes();
  const Bytes doubles = twist_doubles();
  expected.insert(expected.end(), doubles.begin(), doubles.end());
  EXPECT_EQ(cdr.max_wire_size(), 52u);
  EXPECT_EQ(cdr.max_compact_size(), 48u);
  EXPECT_EQ(cdr_write(cdr, doubles), expected);
  EXPECT_EQ(cdr_read(cdr, expected).compact, doubles);
  EXPECT_EQ(cdr.describe(), "XCDR1");
}

TEST(CdrRepresentation, TwistInXcdr2FinalAndAppendable) {
  const Bytes doubles = twist_doubles();
  const CdrRepresentation final_type = cdr_make(twist_type(), DdsRepresentation::xcdr2);
  Bytes plain = ByteText().raw({0x00, 0x07, 0x00, 0x00}).bytes();
  plain.insert(plain.end(), doubles.begin(), doubles.end());
  EXPECT_EQ(cdr_write(final_type, doubles), plain);
  EXPECT_EQ(final_type.describe(), "XCDR2");

  // D_CDR2_LE: a DHEADER before the Twist (56: two nested structs of 4 + 24) and before each Vector3.
  const CdrRepresentation appendable = cdr_make(twist_type(), DdsRepresentation::xcdr2, CdrExtensibility::appendable);
  ByteText delimited;
  delimited.raw({0x00, 0x09, 0x00, 0x00})
      .u32(56)
      .u32(24)
      .f64(1)
      .f64(1.5)
      .f64(-1)
      .u32(24)
      .f64(0.25)
      .f64(-0.125)
      .f64(1001);
  EXPECT_EQ(appendable.max_wire_size(), 64u);
  EXPECT_EQ(cdr_write(appendable, doubles), delimited.bytes());
  EXPECT_EQ(cdr_read(appendable, delimited.bytes()).compact, doubles);
  EXPECT_EQ(appendable.describe(), "XCDR2 appendable");
  // Either reads the other's encoding: the encapsulation header says which.
  EXPECT_EQ(cdr_read(final_type, delimited.bytes()).compact, doubles);
  EXPECT_EQ(cdr_read(appendable, plain).compact, doubles);
}

ChannelType byte_then_double() {
  return cdr_type(
      {cdr_field("flag", cdr_scalar(ScalarKind::uint8)), cdr_field("value", cdr_scalar(ScalarKind::float64))});
}

TEST(CdrRepresentation, AnEightByteValueIsAlignedToEightInXcdr1AndToFourInXcdr2) {
  const Bytes compact = ByteText().u8(7).f64(2.5).bytes();
  const CdrRepresentation xcdr1 = cdr_make(byte_then_double(), DdsRepresentation::xcdr1);
  const Bytes one = ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(7).zeros(7).f64(2.5).bytes();
  EXPECT_EQ(cdr_write(xcdr1, compact), one);
  EXPECT_EQ(xcdr1.max_wire_size(), 20u);
  const CdrRepresentation xcdr2 = cdr_make(byte_then_double(), DdsRepresentation::xcdr2);
  const Bytes two = ByteText().raw({0x00, 0x07, 0x00, 0x00}).u8(7).zeros(3).f64(2.5).bytes();
  EXPECT_EQ(cdr_write(xcdr2, compact), two);
  EXPECT_EQ(xcdr2.max_wire_size(), 16u);
  // Padding is skipped whatever it holds.
  Bytes dirty = one;
  dirty[5] = 0xAA;
  EXPECT_EQ(cdr_read(xcdr1, dirty).compact, compact);
}

TEST(CdrRepresentation, BigEndianInputOfEitherVersion) {
  const Bytes compact = ByteText().u8(7).f64(2.5).bytes();
  const CdrRepresentation cdr = cdr_make(byte_then_double(), DdsRepresentation::xcdr1);
  const Bytes cdr_be = ByteText(true).raw({0x00, 0x00, 0x00, 0x00}).u8(7).zeros(7).f64(2.5).bytes();
  EXPECT_EQ(cdr_read(cdr, cdr_be).compact, compact);
  const Bytes cdr2_be = ByteText(true).raw({0x00, 0x06, 0x00, 0x00}).u8(7).zeros(3).f64(2.5).bytes();
  EXPECT_EQ(cdr_read(cdr, cdr2_be).compact, compact);
  // A string and a sequence count big-endian too.
  const ChannelType type =
      cdr_type({cdr_field("name", cdr_string(8)),
                cdr_field("ids", cdr_collection(FieldType::Kind::sequence, cdr_scalar(ScalarKind::uint16), 4))});
  const CdrRepresentation named = cdr_make(type, DdsRepresentation::xcdr2);
  const Bytes be =
      ByteText(true).raw({0x00, 0x06, 0x00, 0x00}).u32(3).text("ab").u8(0).u8(0).u32(2).u16(0x0102).u16(0x0304).bytes();
  EXPECT_EQ(cdr_read(named, be).compact, ByteText().u32(2).text("ab").u32(2).u16(0x0102).u16(0x0304).bytes());
}

TEST(CdrRepresentation, TranscodesXcdr1InputToXcdr2Output) {
  const CdrRepresentation xcdr2 = cdr_make(byte_then_double(), DdsRepresentation::xcdr2);
  const Bytes xcdr1 = ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(7).zeros(7).f64(2.5).bytes();
  const CdrRead read = cdr_read(xcdr2, xcdr1);
  ASSERT_EQ(read.fault, ConversionFault::none);
  EXPECT_EQ(cdr_write(xcdr2, read.compact), ByteText().raw({0x00, 0x07, 0x00, 0x00}).u8(7).zeros(3).f64(2.5).bytes());
}

TEST(CdrRepresentation, StringsCountTheirNulAndTheOptionsAnnounceThePadding) {
  const ChannelType type = cdr_type({cdr_field("name", cdr_string(8))});
  const CdrRepresentation cdr = cdr_make(type, DdsRepresentation::xcdr1);
  const Bytes compact = ByteText().u32(2).text("hi").bytes();
  // 4 + 3 bytes of body: one byte of padding, announced in the options' last two bits.
  const Bytes wire = ByteText().raw({0x00, 0x01, 0x00, 0x01}).u32(3).text("hi").u8(0).zeros(1).bytes();
  EXPECT_EQ(cdr_write(cdr, compact), wire);
  EXPECT_EQ(cdr_read(cdr, wire).compact, compact);
  EXPECT_EQ(cdr.max_wire_size(), 20u);  // 4 + 4 + 8 + NUL, to a multiple of 4
  const Bytes empty = ByteText().raw({0x00, 0x01, 0x00, 0x03}).u32(1).u8(0).zeros(3).bytes();
  EXPECT_EQ(cdr_read(cdr, empty).compact, ByteText().u32(0).bytes());
  Bytes overlong = empty;
  overlong.insert(overlong.end(), {0, 0, 0, 0});  // more than the announced padding
  EXPECT_EQ(cdr_read(cdr, overlong).fault, ConversionFault::malformed);
}

ChannelType points_type() {
  const FieldType point =
      cdr_record({cdr_field("x", cdr_scalar(ScalarKind::int16)), cdr_field("y", cdr_scalar(ScalarKind::uint8))});
  return cdr_type({cdr_field("points", cdr_collection(FieldType::Kind::sequence, point, 4)),
                   cdr_field("tail", cdr_scalar(ScalarKind::uint8))});
}

Bytes points_compact() { return ByteText().u32(2).u16(1).u8(2).u16(3).u8(4).u8(9).bytes(); }

TEST(CdrRepresentation, SequenceOfStructsInEachEncoding) {
  const Bytes compact = points_compact();
  // XCDR1: count, then each struct at its members' alignment.
  const Bytes one = ByteText().raw({0x00, 0x01, 0x00, 0x00}).u32(2).u16(1).u8(2).zeros(1).u16(3).u8(4).u8(9).bytes();
  EXPECT_EQ(cdr_write(cdr_make(points_type(), DdsRepresentation::xcdr1), compact), one);
  // XCDR2 final: a DHEADER before the sequence (its elements are structs), none before a struct.
  const Bytes two =
      ByteText().raw({0x00, 0x07, 0x00, 0x00}).u32(11).u32(2).u16(1).u8(2).zeros(1).u16(3).u8(4).u8(9).bytes();
  EXPECT_EQ(cdr_write(cdr_make(points_type(), DdsRepresentation::xcdr2), compact), two);
  // XCDR2 appendable: a DHEADER before the top struct, the sequence and each element.
  const Bytes delimited = ByteText()
                              .raw({0x00, 0x09, 0x00, 0x00})
                              .u32(24)
                              .u32(19)
                              .u32(2)
                              .u32(3)
                              .u16(1)
                              .u8(2)
                              .zeros(1)
                              .u32(3)
                              .u16(3)
                              .u8(4)
                              .u8(9)
                              .bytes();
  const CdrRepresentation appendable = cdr_make(points_type(), DdsRepresentation::xcdr2, CdrExtensibility::appendable);
  EXPECT_EQ(cdr_write(appendable, compact), delimited);
  for (const Bytes& wire : {one, two, delimited}) EXPECT_EQ(cdr_read(appendable, wire).compact, compact);
}

TEST(CdrRepresentation, AppendedMembersAreSkippedAShortDheaderIsMalformed) {
  const CdrRepresentation cdr = cdr_make(byte_then_double(), DdsRepresentation::xcdr2, CdrExtensibility::appendable);
  const Bytes compact = ByteText().u8(7).f64(2.5).bytes();
  // A newer version appended a uint32: the DHEADER says 16, our members take 12.
  const Bytes newer = ByteText().raw({0x00, 0x09, 0x00, 0x00}).u32(16).u8(7).zeros(3).f64(2.5).u32(99).bytes();
  EXPECT_EQ(cdr_read(cdr, newer).compact, compact);
  const Bytes shorter = ByteText().raw({0x00, 0x09, 0x00, 0x00}).u32(11).u8(7).zeros(3).f64(2.5).bytes();
  EXPECT_EQ(cdr_read(cdr, shorter).fault, ConversionFault::malformed);
  const Bytes beyond = ByteText().raw({0x00, 0x09, 0x00, 0x00}).u32(13).u8(7).zeros(3).f64(2.5).bytes();
  EXPECT_EQ(cdr_read(cdr, beyond).fault, ConversionFault::malformed);
  // A collection's DHEADER is exactly its size.
  const CdrRepresentation points = cdr_make(points_type(), DdsRepresentation::xcdr2);
  const Bytes loose = ByteText()
                          .raw({0x00, 0x07, 0x00, 0x00})
                          .u32(12)
                          .u32(2)
                          .u16(1)
                          .u8(2)
                          .zeros(1)
                          .u16(3)
                          .u8(4)
                          .zeros(1)
                          .u8(9)
                          .zeros(3)
                          .bytes();
  EXPECT_EQ(cdr_read(points, loose).fault, ConversionFault::malformed);
}

TEST(CdrRepresentation, ArraysOfPrimitivesHaveNoDheaderArraysOfStringsDo) {
  const ChannelType ints =
      cdr_type({cdr_field("a", cdr_collection(FieldType::Kind::array, cdr_scalar(ScalarKind::int32), 3)),
                cdr_field("b", cdr_scalar(ScalarKind::uint8))});
  const Bytes ints_compact = ByteText().u32(1).u32(2).u32(0xFFFFFFFF).u8(5).bytes();
  const Bytes ints_wire = ByteText().raw({0x00, 0x07, 0x00, 0x03}).u32(1).u32(2).u32(0xFFFFFFFF).u8(5).zeros(3).bytes();
  EXPECT_EQ(cdr_write(cdr_make(ints, DdsRepresentation::xcdr2), ints_compact), ints_wire);

  const ChannelType names = cdr_type({cdr_field("n", cdr_collection(FieldType::Kind::array, cdr_string(4), 2))});
  const Bytes names_compact = ByteText().u32(1).text("a").u32(2).text("bc").bytes();
  const Bytes names_wire = ByteText()
                               .raw({0x00, 0x07, 0x00, 0x01})
                               .u32(15)
                               .u32(2)
                               .text("a")
                               .u8(0)
                               .zeros(2)
                               .u32(3)
                               .text("bc")
                               .u8(0)
                               .zeros(1)
                               .bytes();
  const CdrRepresentation cdr = cdr_make(names, DdsRepresentation::xcdr2);
  EXPECT_EQ(cdr_write(cdr, names_compact), names_wire);
  EXPECT_EQ(cdr_read(cdr, names_wire).compact, names_compact);

  // int16[2][3]: one multi-dimensional array, six elements one after the other.
  const ChannelType grid = cdr_type(
      {cdr_field("g", cdr_collection(FieldType::Kind::array,
                                     cdr_collection(FieldType::Kind::array, cdr_scalar(ScalarKind::int16), 3), 2))});
  const Bytes grid_compact = ByteText().u16(1).u16(2).u16(3).u16(4).u16(5).u16(6).bytes();
  EXPECT_EQ(cdr_write(cdr_make(grid, DdsRepresentation::xcdr2), grid_compact),
            ByteText().raw({0x00, 0x07, 0x00, 0x00}).u16(1).u16(2).u16(3).u16(4).u16(5).u16(6).bytes());
}

TEST(CdrRepresentation, A32BitEnumerationIsAnIdlEnumOthersAreIntegers) {
  // XCDR2: a sequence of IDL enums has a DHEADER, a sequence of uint8 "enums" does not.
  const ChannelType type =
      cdr_type({cdr_field("modes", cdr_collection(FieldType::Kind::sequence, cdr_enum(ScalarKind::int32), 2)),
                cdr_field("flags", cdr_collection(FieldType::Kind::sequence, cdr_enum(ScalarKind::uint8), 2))});
  const Bytes compact = ByteText().u32(1).u32(1).u32(2).u8(0).u8(1).bytes();
  const Bytes wire = ByteText().raw({0x00, 0x07, 0x00, 0x02}).u32(8).u32(1).u32(1).u32(2).u8(0).u8(1).zeros(2).bytes();
  EXPECT_EQ(cdr_write(cdr_make(type, DdsRepresentation::xcdr2), compact), wire);
  // A value the enumeration does not name passes, as in the compact layout.
  const Bytes unnamed = ByteText().u32(1).u32(7).u32(0).bytes();
  const CdrRepresentation cdr = cdr_make(type, DdsRepresentation::xcdr1);
  EXPECT_EQ(cdr_read(cdr, cdr_write(cdr, unnamed)).compact, unnamed);
}

TEST(CdrRepresentation, AnEmptySequenceIsItsCountWithoutItsElementsAlignment) {
  const ChannelType type =
      cdr_type({cdr_field("v", cdr_collection(FieldType::Kind::sequence, cdr_scalar(ScalarKind::float64), 3)),
                cdr_field("b", cdr_scalar(ScalarKind::uint8))});
  const CdrRepresentation cdr = cdr_make(type, DdsRepresentation::xcdr1);
  const Bytes compact = ByteText().u32(0).u8(3).bytes();
  const Bytes wire = ByteText().raw({0x00, 0x01, 0x00, 0x03}).u32(0).u8(3).zeros(3).bytes();
  EXPECT_EQ(cdr_write(cdr, compact), wire);
  EXPECT_EQ(cdr_read(cdr, wire).compact, compact);
  EXPECT_EQ(cdr.max_wire_size(), 4u + 8 + 24 + 4);  // count, padding to 8, three doubles, the uint8 padded
}

TEST(CdrRepresentation, MalformedSamples) {
  const ChannelType type =
      cdr_type({cdr_field("on", cdr_scalar(ScalarKind::boolean)), cdr_field("name", cdr_string(3)),
                cdr_field("ids", cdr_collection(FieldType::Kind::sequence, cdr_scalar(ScalarKind::uint8), 2))});
  const CdrRepresentation cdr = cdr_make(type, DdsRepresentation::xcdr1);
  const auto sample = [](std::uint8_t on, std::uint32_t length, const std::string& name, std::uint32_t count) {
    ByteText b;
    b.raw({0x00, 0x01, 0x00, 0x00}).u8(on).zeros(3).u32(length).text(name);
    while ((b.bytes().size() - 4) % 4 != 0) b.u8(0);
    b.u32(count).u8(1).u8(2);
    const std::size_t body = b.bytes().size() - 4;
    Bytes out = b.zeros((4 - body % 4) % 4).bytes();
    out[3] = static_cast<std::uint8_t>((4 - body % 4) % 4);
    return out;
  };
  const std::string nul(1, '\0');
  ASSERT_EQ(cdr_read(cdr, sample(1, 4, "abc" + nul, 2)).fault, ConversionFault::none);
  EXPECT_EQ(cdr_read(cdr, sample(2, 4, "abc" + nul, 2)).fault, ConversionFault::malformed);   // bool 2
  EXPECT_EQ(cdr_read(cdr, sample(1, 5, "abcd" + nul, 2)).fault, ConversionFault::malformed);  // string over its bound
  EXPECT_EQ(cdr_read(cdr, sample(1, 4, "abcd", 2)).fault, ConversionFault::malformed);        // no NUL
  EXPECT_EQ(cdr_read(cdr, sample(1, 0, "", 2)).fault, ConversionFault::malformed);            // length 0: no NUL
  EXPECT_EQ(cdr_read(cdr, sample(1, 4, "abc" + nul, 3)).fault, ConversionFault::malformed);   // count over its bound

  const Bytes good = sample(1, 4, "abc" + nul, 2);
  for (std::size_t cut = 0; cut < good.size() - 2; ++cut) {  // the last 2 bytes are announced padding
    const Bytes short_sample(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_EQ(cdr_read(cdr, short_sample).fault, ConversionFault::malformed) << cut;
  }
  Bytes trailing = good;
  trailing.insert(trailing.end(), {0, 0, 0, 0});
  EXPECT_EQ(cdr_read(cdr, trailing).fault, ConversionFault::malformed);
  Bytes overpadded = good;
  overpadded[3] = 3;  // announces more padding than there is after the members
  EXPECT_EQ(cdr_read(cdr, overpadded).fault, ConversionFault::malformed);
  // Encapsulations that are not a plain CDR one: PL_CDR_LE, PL_CDR2_LE, XML, XTypes 1.3 Table 60's CDR2_LE.
  for (const std::uint8_t id : {0x03, 0x0b, 0x04, 0x11}) {
    Bytes other = good;
    other[1] = id;
    EXPECT_EQ(cdr_read(cdr, other).fault, ConversionFault::malformed) << int{id};
  }
}

TEST(CdrRepresentation, UnannouncedPaddingToAMultipleOfFourIsAccepted) {
  // Fast DDS 2.x announces no padding; its readers pass the RTPS submessage's padding on.
  const CdrRepresentation cdr =
      cdr_make(cdr_type({cdr_field("b", cdr_scalar(ScalarKind::uint8))}), DdsRepresentation::xcdr1);
  EXPECT_EQ(cdr_read(cdr, ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(4).zeros(3).bytes()).compact, Bytes{4});
  EXPECT_EQ(cdr_read(cdr, ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(4).bytes()).compact, Bytes{4});
  EXPECT_EQ(cdr_read(cdr, ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(4).zeros(2).bytes()).fault,
            ConversionFault::malformed);  // not to a multiple of 4
  EXPECT_EQ(cdr_read(cdr, ByteText().raw({0x00, 0x01, 0x00, 0x00}).u8(4).zeros(7).bytes()).fault,
            ConversionFault::malformed);
}

TEST(CdrRepresentation, BuffersBelowTheBoundsAreTooSmall) {
  const CdrRepresentation cdr = cdr_make(byte_then_double(), DdsRepresentation::xcdr1);
  const Bytes compact = ByteText().u8(7).f64(2.5).bytes();
  Bytes wire(cdr.max_wire_size() - 1);
  EXPECT_EQ(cdr.from_compact(compact, wire).fault, ConversionFault::too_small);
  Bytes small(cdr.max_compact_size() - 1);
  EXPECT_EQ(cdr.to_compact(cdr_write(cdr, compact), small).fault, ConversionFault::too_small);
}

TEST(CdrRepresentation, FromCompactRefusesWhatCheckCompactRefuses) {
  const ChannelType type = points_type();
  const CdrRepresentation cdr = cdr_make(type, DdsRepresentation::xcdr2);
  Bytes over = points_compact();
  over[0] = 5;  // five points, bound 4
  Bytes longer = points_compact();
  longer.push_back(0);
  Bytes shorter = points_compact();
  shorter.pop_back();
  for (const Bytes& compact : {over, longer, shorter}) {
    EXPECT_FALSE(check_compact(type, compact).ok());
    EXPECT_TRUE(cdr_write(cdr, compact).empty());
  }
  const ChannelType flags = cdr_type({cdr_field("on", cdr_scalar(ScalarKind::boolean))});
  EXPECT_TRUE(cdr_write(cdr_make(flags, DdsRepresentation::xcdr1), Bytes{2}).empty());
}

TEST(CdrRepresentation, MakeRefusesConditionalFieldsAndUnsoundTypes) {
  ChannelType type =
      cdr_type({cdr_field("mode", cdr_scalar(ScalarKind::uint8)), cdr_field("dtc", cdr_scalar(ScalarKind::uint16))});
  type.fields[1].present_when = FieldPresence{"mode", 0};
  const auto conditional = CdrRepresentation::make(type, DdsRepresentation::xcdr2, CdrExtensibility::final_type);
  ASSERT_FALSE(conditional.ok());
  EXPECT_NE(conditional.error().text.find("field dtc is conditional"), std::string::npos) << conditional.error().text;
  const auto unsound = CdrRepresentation::make(cdr_type({cdr_field("s", cdr_string(0))}), DdsRepresentation::xcdr1,
                                               CdrExtensibility::final_type);
  EXPECT_FALSE(unsound.ok());
}

}  // namespace
}  // namespace cdr_test
}  // namespace cosmic

// The type of a channel's contents (issue 35; the paper's Fig. 7, "Contents"): a record of named
// fields, each a scalar (bool, signed and unsigned integers of 8 to 64 bits, float32, float64),
// an enumeration with named values, a bounded string, a fixed array, a bounded sequence or a nested
// record. A numeric field may carry a unit and a range. Each network's representation of the
// channel (a DBC frame, an IDL struct in CDR, an LCM type, JSON) is written against this type.
//
// Plain values without I/O: the configuration builds them (inline YAML; the type files of DBC, IDL,
// ROS 2 .msg and LCM come next) and checks them with check_type(); any thread may read them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosmic/dbc.hpp"
#include "cosmic/e2e_protection.hpp"

namespace cosmic {

struct LcmTypeFile;  // cosmic/lcm_types.hpp

enum class ScalarKind : std::uint8_t {
  boolean,
  int8,
  int16,
  int32,
  int64,
  uint8,
  uint16,
  uint32,
  uint64,
  float32,
  float64,
};

// The YAML and text spelling: "bool", "int8", ..., "float64".
std::string_view scalar_name(ScalarKind kind);
std::optional<ScalarKind> scalar_kind(std::string_view name);
bool is_integer(ScalarKind kind);
bool is_signed_integer(ScalarKind kind);
// The values the kind holds: [lowest, highest] (bool: 0..1; floats: their finite range).
std::pair<double, double> scalar_limits(ScalarKind kind);

struct EnumValue {
  std::string name;
  std::int64_t value = 0;
  friend bool operator==(const EnumValue&, const EnumValue&) = default;
};

struct TypeField;

struct FieldType {
  enum class Kind : std::uint8_t { scalar, enumeration, string, array, sequence, record };
  Kind kind = Kind::scalar;
  ScalarKind scalar = ScalarKind::float64;  // scalar; an enumeration's underlying integer
  std::vector<EnumValue> values;            // enumeration: its named values, as declared
  std::uint32_t bound = 0;                  // string: most bytes; array: its length; sequence: most elements
  std::vector<FieldType> element;           // array and sequence: exactly one, the element's type
  std::vector<TypeField> fields;            // record: its fields, in order
  friend bool operator==(const FieldType&, const FieldType&) = default;
};

// A field its record carries only while another field, its selector, holds one value: a DBC
// message's multiplexed signals (the selector is the multiplexor switch). The selector is an integer
// or enumeration field declared earlier in the same record that is always present.
struct FieldPresence {
  std::string selector;
  std::int64_t value = 0;
  friend bool operator==(const FieldPresence&, const FieldPresence&) = default;
};

struct TypeField {
  std::string name;
  FieldType type;
  std::string unit;               // a numeric field's (or numeric elements') unit, e.g. "m/s"; empty: none
  std::optional<double> minimum;  // a numeric field's declared range, within its kind's limits
  std::optional<double> maximum;
  std::optional<FieldPresence> present_when;  // none: always present
  friend bool operator==(const TypeField&, const TypeField&) = default;
};

// Where a type was read from, when not written inline: the configuration writes it back this way
// (a bind or state file names the DBC message or the LCM struct, not its fields).
struct TypeSource {
  enum class Format : std::uint8_t { dbc, lcm, idl, msg };
  Format format = Format::dbc;
  std::string file;  // as resolved against the configuration's directory
  // The DBC message's name, the LCM struct's full name (pkg.name_t), the IDL struct's scoped name
  // (pkg::msg::Name) or the ROS 2 message's (pkg/msg/Name).
  std::string name;
  // LCM: bounds of variable-length arrays, by member; IDL, .msg: of strings and sequences, by path.
  std::map<std::string, std::uint32_t> max_length;
  // What the source's own representation needs beyond the fields, read with them and compared by
  // content (a file changed under a reload rebinds the channel): a DBC message's frame layout; the
  // LCM file's structs (the struct's nested structs and which member counts which array). Shared:
  // every copy of a channel's spec refers to the one file read.
  std::optional<DbcMessage> dbc_message;
  std::shared_ptr<const LcmTypeFile> lcm_file;
  // IDL and .msg: where included files and referenced messages are looked for (as given, resolved),
  // and whether the IDL struct is @appendable (its CDR hops then write XCDR2 with DHEADERs).
  std::vector<std::string> type_path{};
  bool appendable = false;
  // DBC: the message's end-to-end protection (cosmic/e2e_protection.hpp); its counter and CRC
  // signals are then not fields of the type, dbc_message keeps them.
  std::optional<E2eSpec> e2e{};
  friend bool operator==(const TypeSource& a, const TypeSource& b);
};

// What to do with a value a hop's representation cannot hold (a DBC signal too narrow, a scaled
// value beyond its raw bits; channel key `on_range`): drop the event on that hop and count it
// (`out_of_range`), or send the nearest value the representation holds.
enum class RangePolicy : std::uint8_t { drop, saturate };

struct ChannelType {
  std::vector<TypeField> fields;
  std::optional<TypeSource> source;  // none: declared inline
  friend bool operator==(const ChannelType&, const ChannelType&) = default;
};

// Bounds a type stays within, so a hostile or mistaken file cannot make a type that costs without
// limit to check, convert or show.
inline constexpr std::size_t kMaxTypeDepth = 8;                // records and element types nested
inline constexpr std::size_t kMaxRecordFields = 256;           // fields of one record
inline constexpr std::uint32_t kMaxTypeBound = 65'536;         // array length, sequence and string bounds
inline constexpr std::size_t kMaxEnumValues = 1024;            // named values of one enumeration
inline constexpr std::uint64_t kMaxFlattenedScalars = 65'536;  // scalars of the largest value, arrays expanded

// A field's name, as DDS, ROS 2 and LCM accept it: [A-Za-z][A-Za-z0-9_]*, at most 64 characters.
bool valid_field_name(std::string_view name);

// What is wrong with a type, one problem per entry, each naming where ("fields[2].element",
// "pose.x"); empty when the type is sound: names valid and unique per record, enumerations with
// unique names and values their underlying integer holds, bounds and arrays at least 1 and at most
// kMaxTypeBound, element types present exactly where needed, units and ranges only on numeric
// fields, ranges within their kind and not reversed, nesting and size within the bounds above, a
// presence condition's selector an earlier, always present integer or enumeration field of the same
// record whose kind holds the value.
struct TypeProblem {
  std::string where;
  std::string what;
  friend bool operator==(const TypeProblem&, const TypeProblem&) = default;
};
std::vector<TypeProblem> check_type(const ChannelType& type);

// Whether the type (or its elements) is a number: an integer, a float, or bool.
bool is_numeric(const FieldType& type);

// How `cosmicctl channel` and errors show a type: "float64", "uint8[4]", "sequence<int32, 10>",
// "string<=32>", "enum int32 {OFF=0, ON=1}", "{x: float64, y: float64}", "{mode: uint8, dtc:
// uint16 when mode=0}".
std::string describe(const FieldType& type);
// "distance: float32 [m, 0..40]", "dtc: uint16 when mode=0".
std::string describe(const TypeField& field);
std::string describe(const ChannelType& type);

// The shortest text that reads back as the same double (ranges in errors, descriptions and YAML).
std::string shortest_number_text(double value);

}  // namespace cosmic

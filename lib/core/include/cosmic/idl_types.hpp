// OMG IDL type files (issue 35; `type: {idl: FILE, name: pkg::msg::Name}`): the subset ROS 2's
// rosidl generates (geometry_msgs/msg/Twist.idl, sensor_msgs/msg/LaserScan.idl, ...) and what users
// of Cyclone DDS's idlc write, and a struct as a typed channel's contents. Pure: parses text, no
// file I/O (a caller's loader reads the #included files); never throws; bounded by the limits below
// so that a hostile file costs little. The configuration and `cosmicctl types` call it on their
// own thread; it keeps no state, so any number of threads may call it at once, and the loader is
// called on the calling thread, during parse_idl_types() only.
//
// Read: modules (nested, reopened across files), structs, nested structs by scoped name (relative
// to the enclosing modules, or absolute with a leading "::"), enums (@value(N) or counting from
// 0), typedefs (of arrays too), `const` declarations of integers, floats, booleans and strings
// (kept as constants, not fields: rosidl puts a message's constants in `module Name_Constants`),
// fixed arrays of any dimension, sequence<T> and sequence<T, N>, string and string<N>, the integer
// types (short, long, long long, their unsigned forms, int8..uint64, octet), boolean, float,
// double and char. Bounds and dimensions are integer literals or integer constants.
// Annotations: @unit("m"), @range(min=, max=), @min, @max become the field's unit and range;
// @default and @verbatim(language="comment") are kept (not part of the type); @final and
// @appendable (or @extensibility(...)) give the struct's extensibility; @key(FALSE) and
// @optional(FALSE) change nothing; other annotations that leave the serialized form alone are
// ignored.
//
// Refused, each with its location and reason: @key (keyed types: the gateway does not compute key
// hashes), @optional, @mutable, @non_serialized, @bit_bound other than 32, unions, wchar and
// wstring, long double, fixed, map, any, struct inheritance and forward declarations, and every
// declaration kind beyond the above (interface, valuetype, bitmask, ...).
//
// Decisions, where IDL leaves a choice or the gateway needs one:
//  - char reads as int8: one byte whose signedness IDL leaves open, C's char on the gateway's hosts.
//  - An unannotated struct is @final. XTypes 1.3 makes appendable the default, but ROS 2's rmw
//    layers serialize rosidl's (unannotated) types as final, plain XCDR1 (encapsulation CDR_LE),
//    and idlc 0.10's default is final too; a user who means appendable writes @appendable.
//  - A typed channel's strings and sequences are bounded: an unbounded one (string, sequence<T>)
//    gets kMaxTypeBound, the most a channel's type allows, unless max_length bounds it tighter (by
//    member path, as the LCM reader's variable-length arrays are). A struct with two unbounded
//    sequences of numbers then exceeds kMaxFlattenedScalars, and is refused with a hint to bound them.
//  - #include "name" and <name>: the loader reads the file by the name as written (the caller
//    resolves it against its directories, as idlc's -I does); each name is read once, the first
//    time (as rosidl's own parser reads each file once). Without a loader the names are only
//    recorded. An include must stand outside every module and struct.
//  - #pragma: `#pragma keylist` declares keys and is refused; other pragmas are ignored. The
//    include guard (#ifndef X / #define X as the file's first directives, #endif as its last) is
//    read as the no-op it is; every other directive (#define, #if, #ifdef, ...) is refused: this is
//    no preprocessor, and a condition read wrongly would change the type silently.
//  - Names are case-sensitive. IDL makes names that differ only in case collide (idlc refuses a
//    member `color` of type `Color` used again after it); this reader does not check that rule,
//    which changes no type it reads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/cdr_representation.hpp"  // CdrExtensibility
#include "cosmic/channel_type.hpp"

namespace cosmic {

// A located problem: the file (the #include name as written; empty: the text given to
// parse_idl_types), its line and column (line 0: the file as a whole).
struct IdlError {
  std::string file;
  int line = 0, column = 0;
  std::string message;
  friend bool operator==(const IdlError&, const IdlError&) = default;
};

// A type as a declaration names it, resolved when the file was read.
struct IdlType {
  enum class Kind : std::uint8_t { primitive, string, sequence, structure, enumeration, alias };
  Kind kind = Kind::primitive;
  ScalarKind scalar = ScalarKind::int32;  // primitive: the scalar it reads as
  // primitive: its IDL spelling, one blank between words ("unsigned long", "octet");
  // structure, enumeration, alias (a typedef): the declared type's scoped name ("pkg::msg::Name").
  std::string name;
  std::uint32_t bound = 0;       // string, sequence: the declared bound; 0: unbounded
  std::vector<IdlType> element;  // sequence: exactly one
  friend bool operator==(const IdlType&, const IdlType&) = default;
};

struct IdlMember {
  std::string name;
  IdlType type;
  std::vector<std::uint32_t> dimensions;   // a fixed array's, outermost first; empty: none
  std::string unit;                        // @unit
  std::optional<double> minimum, maximum;  // @range, @min, @max
  std::string default_value;               // @default, as written
  std::string comment;                     // @verbatim(language="comment")
  int line = 0, column = 0;                // of the member's name
  friend bool operator==(const IdlMember&, const IdlMember&) = default;
};

struct IdlStruct {
  std::string name;  // scoped: "geometry_msgs::msg::Twist"
  std::vector<IdlMember> members;
  CdrExtensibility extensibility = CdrExtensibility::final_type;
  bool extensibility_declared = false;  // false: unannotated, final by the rule above
  std::string comment;
  std::string file;
  int line = 0, column = 0;  // of the `struct` keyword
  friend bool operator==(const IdlStruct&, const IdlStruct&) = default;
};

struct IdlEnum {
  std::string name;
  std::vector<EnumValue> values;  // declaration order
  std::string file;
  int line = 0, column = 0;
  friend bool operator==(const IdlEnum&, const IdlEnum&) = default;
};

struct IdlTypedef {
  std::string name;
  IdlType type;
  std::vector<std::uint32_t> dimensions;
  std::string file;
  int line = 0, column = 0;
  friend bool operator==(const IdlTypedef&, const IdlTypedef&) = default;
};

struct IdlConstant {
  std::string name;  // scoped: "pkg::msg::Name_Constants::LIMIT"
  IdlType type;      // a primitive or a string
  // Integers in decimal, floats as written (with their sign), booleans TRUE or FALSE, strings their
  // characters (escapes resolved).
  std::string value;
  std::string comment;
  std::string file;
  int line = 0, column = 0;
  friend bool operator==(const IdlConstant&, const IdlConstant&) = default;
};

struct IdlTypeFile {
  std::vector<std::string> includes;  // every #include name, in the order first met
  std::vector<IdlStruct> structs;     // reading order, included files' at their #include
  std::vector<IdlEnum> enums;
  std::vector<IdlTypedef> typedefs;
  std::vector<IdlConstant> constants;
  std::vector<IdlError> errors;  // every problem found (capped, with one closing line counting the rest)
  bool ok() const { return errors.empty(); }
  // By scoped name, "pkg::msg::Name" or "::pkg::msg::Name".
  const IdlStruct* find(std::string_view scoped_name) const;
  const IdlEnum* find_enum(std::string_view scoped_name) const;
  const IdlTypedef* find_typedef(std::string_view scoped_name) const;
  const IdlConstant* find_constant(std::string_view scoped_name) const;
  friend bool operator==(const IdlTypeFile&, const IdlTypeFile&) = default;
};

inline constexpr std::size_t kIdlMaxTextBytes = std::size_t{1} << 20;   // one file
inline constexpr std::size_t kIdlMaxTotalBytes = std::size_t{4} << 20;  // a file and its includes
inline constexpr std::size_t kIdlMaxFiles = 256;                        // included files read
inline constexpr std::size_t kIdlMaxIncludeDepth = 16;                  // files including files
inline constexpr std::size_t kIdlMaxDeclarations = 4'000;               // structs, enums, typedefs, constants
inline constexpr std::size_t kIdlMaxMembers = 256;                      // of one struct, as a record has
inline constexpr std::size_t kIdlMaxModuleDepth = 16;                   // modules in modules
inline constexpr std::size_t kIdlMaxDimensions = 8;                     // of one array
inline constexpr std::size_t kIdlMaxTypeNodes = 65'536;                 // of one channel type, built

// Reads an included file by its #include name; nullopt: there is no such file (or it cannot be
// read: the caller's own errors are its to report).
using IdlIncludeLoader = std::function<std::optional<std::string>(std::string_view include_name)>;

IdlTypeFile parse_idl_types(std::string_view text, const IdlIncludeLoader& load = nullptr);

// The scalar an IDL primitive type reads as ("unsigned long" -> uint32, "octet" -> uint8, "char"
// -> int8, "int16" -> int16, ...; words separated by one blank); nullopt for anything else.
std::optional<ScalarKind> idl_scalar_kind(std::string_view idl_name);

// The struct as a typed channel's contents, and the extensibility its CDR representation takes
// (every nested struct must have the same: CdrRepresentation gives the whole type one).
// `max_length` bounds strings and sequences by member path: "frame_id", "header.frame_id", a
// sequence's or array's elements with "[]" ("names[]", "poses[].header.frame_id"); a bound is
// 1..the declared one (kMaxTypeBound when unbounded). Problems are located at the member (or the
// struct); where the members could be read, `type` holds them even then.
struct IdlChannelType {
  ChannelType type;
  CdrExtensibility extensibility = CdrExtensibility::final_type;
  std::vector<IdlError> errors;
  bool ok() const { return errors.empty(); }
};
IdlChannelType idl_channel_type(const IdlTypeFile& file, const IdlStruct& s,
                                const std::map<std::string, std::uint32_t>& max_length = {});

}  // namespace cosmic

// LCM type files (issue 35; `type: {lcm: FILE, name: pkg.type_t}`): what lcm-gen reads, the structs
// of a `.lcm` file with their members (primitive types, structs of the same file, fixed and
// variable-length arrays of any dimension) and constants, each struct's fingerprint computed as
// lcm-gen computes it, and a struct as a typed channel's contents. Pure: parses text, no file I/O;
// never throws; bounded by the limits below so that a hostile file costs little.
//
// A struct's field types: int8_t..int64_t as int8..int64, byte as uint8, float and double as
// float32 and float64, boolean as bool, string as a string of at most kLcmStringBound bytes, a
// struct as a record; a fixed dimension an array, a variable one (`ranges[num_ranges]`) a sequence
// bounded by what its count member's type holds, at most kLcmSequenceBound (a configuration may
// bound it tighter). The count member stays a field of its own, as LCM sends it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/dbc.hpp"  // DbcError: a located problem in a text file

namespace cosmic {

using LcmError = DbcError;

struct LcmDimension {
  bool variable = false;  // sized by a member of the struct (its name in `size`)
  std::string size;       // the decimal length, or the member's name, as written
  friend bool operator==(const LcmDimension&, const LcmDimension&) = default;
};

struct LcmMember {
  std::string name;
  std::string type;  // a primitive's name (int32_t, string, ...) or a struct's full name (pkg.name_t)
  std::vector<LcmDimension> dimensions;
  int line = 0, column = 0;
  friend bool operator==(const LcmMember&, const LcmMember&) = default;
};

struct LcmConstant {
  std::string name;
  std::string type;
  std::string value;  // as written
  int line = 0, column = 0;
  friend bool operator==(const LcmConstant&, const LcmConstant&) = default;
};

struct LcmStruct {
  std::string package;  // empty: none
  std::string name;
  std::vector<LcmMember> members;
  std::vector<LcmConstant> constants;
  int line = 0, column = 0;  // of the `struct` keyword
  std::string full_name() const { return package.empty() ? name : package + "." + name; }
  friend bool operator==(const LcmStruct&, const LcmStruct&) = default;
};

struct LcmTypeFile {
  std::vector<LcmStruct> structs;  // file order
  std::vector<LcmError> errors;    // every problem found (capped, with one closing line counting the rest)
  bool ok() const { return errors.empty(); }
  const LcmStruct* find(std::string_view full_name) const;
};

inline constexpr std::size_t kLcmMaxTextBytes = std::size_t{1} << 20;
inline constexpr std::size_t kLcmMaxStructs = 1'000;
inline constexpr std::size_t kLcmMaxMembers = 256;  // of one struct, as a record has at most
inline constexpr std::size_t kLcmMaxDimensions = 8;
inline constexpr std::uint32_t kLcmStringBound = 65'536;
inline constexpr std::uint32_t kLcmSequenceBound = 65'536;

LcmTypeFile parse_lcm_types(std::string_view text);

bool lcm_is_primitive(std::string_view type);

// The hash lcm-gen computes of a struct alone: its members' names, primitive types and dimensions.
std::int64_t lcm_base_hash(const LcmStruct& s);
// The 64-bit fingerprint an LCM message of the struct starts with (the struct's and its nested
// structs' hashes, rotated as lcm-gen's generated code does); nullopt when a nested struct is not
// in the file.
std::optional<std::uint64_t> lcm_fingerprint(const LcmTypeFile& file, const LcmStruct& s);

// The struct as a typed channel's contents; `max_length` bounds variable-length arrays by member
// name (at most what the count's type and kLcmSequenceBound allow). Problems are located at the
// member (or the struct); where the members could be read, `type` holds them even then (so a tool
// can show what a struct holds before its arrays are bounded).
struct LcmChannelType {
  ChannelType type;
  std::vector<LcmError> errors;
  bool ok() const { return errors.empty(); }
};
LcmChannelType lcm_channel_type(const LcmTypeFile& file, const LcmStruct& s,
                                const std::map<std::string, std::uint32_t>& max_length = {});

}  // namespace cosmic

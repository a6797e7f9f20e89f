// ROS 2 message files (issue 35; `type: {msg: FILE, name: pkg/msg/Name}` with its dependencies on
// `type_path:`): a `.msg` file read as rosidl_adapter (ROS 2's own reader, rosidl 3.3) reads it,
// and a message as a typed channel's contents: the ChannelType whose CDR form
// (cosmic/cdr_representation.hpp) is the IDL struct rosidl generates from the file, the struct
// ROS 2's rmw serializes (XCDR1, final). Pure: parses text and asks the caller for the text of
// each message a message refers to, no file I/O; never throws; bounded by the limits below so
// that a hostile file costs little. Called on the configuration's thread (or by a tool); the
// results are plain values any thread may read.
//
// The syntax, as rosidl_adapter.parser reads it, one definition a line:
//   TYPE NAME [DEFAULT]       a field, with an optional default value (recorded, not used)
//   TYPE NAME=VALUE           a constant (any line whose rest holds '='): not a field
//   # ...                     a comment, from the first '#' of the line on (even inside quotes)
// Tabs read as spaces; a line that starts with a blank holds only a comment (rosidl refuses an
// indented definition). Names as ROS 2 allows them: packages and fields [a-z][a-z0-9_]* without
// "__" or a final '_', messages [A-Z][A-Za-z0-9]*, constants [A-Z][A-Z0-9_]* without "__" or a
// final '_'. A comment with exactly one "[...]" (no ',' inside) gives its field's unit, as rosidl
// gives the IDL member its @unit: the comment on the field's line, the whole-line comments right
// before it and the indented comment lines after it (not the file's leading comment block).
//
// Types and their place in the channel type (rosidl's .msg-to-IDL mapping):
//   bool -> bool; byte (IDL octet) and char (IDL uint8) -> uint8; int8..uint64 -> the same;
//   float32, float64 -> float32, float64; string -> string (bound below); string<=N -> string of
//   at most N bytes; pkg/Name, or Name for a message of the same package -> a nested record;
//   T[N] -> an array of N; T[<=N] -> a sequence of at most N; T[] -> a sequence (bound below).
//   A message without fields is the struct rosidl generates for it: one uint8 member
//   `structure_needs_at_least_one_member`.
// Refused, with the reason: wstring (a channel's strings are bytes, and a wide string's CDR form
// changed between DDS-XTypes 1.1 and 1.2, on which ROS 2's DDS implementations have disagreed:
// ros2/rmw_cyclonedds#43, #121),
// ROS 1's time and duration (rosidl has no IDL type for them: builtin_interfaces/Time and
// builtin_interfaces/Duration are ROS 2's), multi-dimensional arrays, `pkg/msg/Name` inside a file
// (rosidl reads only pkg/Name there), bounds and lengths beyond kMaxTypeBound.
//
// A bare `Header` is a message of the file's own package, as in rosidl: ROS 1 read it as
// std_msgs/Header, ROS 2 does not (its common_interfaces write std_msgs/Header). When the package
// has no Header the error says so and names std_msgs/Header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/dbc.hpp"  // DbcError: a located problem in a text file

namespace cosmic {

using MsgError = DbcError;

// A field's type as written: a primitive or a message, maybe an array of them.
struct MsgFieldType {
  std::string package;             // a message's package; empty: a primitive, or a message of the file's own package
  std::string name;                // a primitive's name ("float64", "string", "char") or a message's ("Vector3")
  std::uint32_t string_bound = 0;  // string<=N: N; 0: an unbounded string (or not a string)
  enum class Array : std::uint8_t { none, fixed, bounded, unbounded };
  Array array = Array::none;
  std::uint32_t array_size = 0;  // fixed: the length; bounded: the most elements
  bool is_primitive() const;
  friend bool operator==(const MsgFieldType&, const MsgFieldType&) = default;
};

struct MsgField {
  MsgFieldType type;
  std::string name;
  std::optional<std::string> default_value;  // as written (checked as rosidl checks it, then not used)
  std::string unit;                          // from the comments, as rosidl finds it; empty: none
  int line = 0, column = 0;                  // of the field's type (the line's start)
  friend bool operator==(const MsgField&, const MsgField&) = default;
};

struct MsgConstant {
  std::string type;  // a primitive's name
  std::string name;
  std::string value;  // as written
  int line = 0, column = 0;
  friend bool operator==(const MsgConstant&, const MsgConstant&) = default;
};

struct MsgFile {
  std::vector<MsgField> fields;        // file order
  std::vector<MsgConstant> constants;  // file order
  std::vector<MsgError> errors;        // every problem found (capped, with one closing line counting the rest)
  bool ok() const { return errors.empty(); }
};

inline constexpr std::size_t kMsgMaxTextBytes = std::size_t{1} << 20;
inline constexpr std::size_t kMsgMaxFields = kMaxRecordFields;  // of one message
inline constexpr std::size_t kMsgMaxConstants = 1'024;
inline constexpr std::size_t kMsgMaxFiles = 256;  // messages one channel type reads, itself included

// One .msg file's text. Errors are located at line and column (1-based, bytes); line 0 only for
// the text's size and the closing count.
MsgFile parse_msg(std::string_view text);

// A message's full name: "pkg/msg/Name" (or "pkg/Name", as a .msg file writes it) split into its
// package and name, both valid ROS 2 names; nullopt otherwise.
struct MsgTypeName {
  std::string package, name;
  std::string full() const { return package + "/msg/" + name; }
  friend bool operator==(const MsgTypeName&, const MsgTypeName&) = default;
};
std::optional<MsgTypeName> msg_type_name(std::string_view text);

// The definitions of builtin_interfaces/Time and builtin_interfaces/Duration (int32 sec, uint32
// nanosec), as rcl_interfaces ships them, which msg_channel_type uses when the loader does not find
// them (a type path need not hold ROS 2's own packages); nullopt for any other message.
std::optional<std::string_view> msg_builtin_text(std::string_view package, std::string_view name);

// The text of package/msg/name.msg, or nullopt when there is none. The caller searches its type
// path; it is called on the caller's thread, at most once per message.
using MsgLoader = std::function<std::optional<std::string>(const std::string& package, const std::string& name)>;

// A problem of a message's type, in the file it comes from: `file` is that message's
// "pkg/msg/Name" (the caller names the path it loaded for it); line 0 where no line is to blame (a
// message not found, max_length, a limit of the whole type).
struct MsgTypeError {
  std::string file;
  int line = 0, column = 0;
  std::string message;
  friend bool operator==(const MsgTypeError&, const MsgTypeError&) = default;
};

struct MsgSourceFile {
  std::string name;       // "pkg/msg/Name"
  bool built_in = false;  // msg_builtin_text's definition, the loader having none
  friend bool operator==(const MsgSourceFile&, const MsgSourceFile&) = default;
};

struct MsgChannelType {
  ChannelType type;                  // as far as it could be built (so a tool can show it even with errors)
  std::vector<MsgTypeError> errors;  // capped like a file's
  std::vector<MsgSourceFile> files;  // every message read, the requested one first
  bool ok() const { return errors.empty(); }
};

// The message `package`/msg/`name` as a typed channel's contents, every message it refers to read
// through `load` (the requested one too), recursively: at most kMsgMaxFiles messages, nested at
// most kMaxTypeDepth deep, none containing itself. An unbounded string or sequence is bounded by
// kMaxTypeBound unless `max_length` bounds it tighter (1..kMaxTypeBound) by its member path: field
// names joined by '.', "[]" after a field to step into its elements ({ranges: 1081,
// "header.frame_id": 64, "names[]": 32, "points[].label": 16}). A path that names no unbounded
// string or sequence is an error. A type whose largest value exceeds check_type's limits (two
// unbounded float32 sequences do) is refused with a hint to bound them.
MsgChannelType msg_channel_type(const std::string& package, const std::string& name, const MsgLoader& load,
                                const std::map<std::string, std::uint32_t>& max_length = {});

}  // namespace cosmic

// The ROS 2 message definition of a typed channel (issue 37): what cosmicd puts in an MCAP Schema
// record of encoding `ros2msg` when it records a typed channel's events as CDR (message encoding
// `cdr`), so that Foxglove, rosbag2 and other ROS 2 tools decode the recorded fields. The
// definition reads exactly the bytes cosmic::CdrRepresentation writes for the type in XCDR1
// (final, little-endian: what ROS 2's rmw writes); checked against npm's @foxglove/rosmsg and
// @foxglove/rosmsg2-serialization (tests/mcap).
//
// The text is laid out as rosbag2 writes it and the MCAP specification's appendix "ros2msg" reads
// it: the top message's definition, then each nested message after a line of 80 '=' and a line
// `MSG: pkg/Name`. The mapping, field by field:
//   bool, int8..uint64, float32, float64   the ROS 2 primitive of the same name
//   enumeration                            its underlying integer (a 32-bit one is an IDL enum in
//                                          CDR: 4 bytes, so int32 or uint32), its named values as
//                                          constants before the field when every name is a valid
//                                          ROS 2 constant name not used yet in that message
//   string of at most N bytes              string<=N
//   array of N                             T[N]; an array of arrays is one flat array of the product
//                                          of the lengths (CDR writes a multi-dimensional array as
//                                          its elements in row-major order, the same bytes)
//   sequence of at most N                  T[<=N]
//   record                                 a nested message (names below)
// A unit is written as rosidl reads it back: a comment `# [unit]` after the field.
//
// Names. The schema's name is `pkg/msg/Name`: a type read from a ROS 2 .msg file keeps its own
// (TypeSource::name); any other is `cosmic/msg/<the channel's name in CamelCase>`. A channel type
// does not keep the names of its nested records, so each nested message is named after where it
// sits, in the top message's package: `<its parent's name><the field's name in CamelCase>`
// (`cosmic/RangePose`), with a number appended should two places give the same name.
//
// Refused, with the reason (the recorder then writes the channel as JSON): a type check_type()
// refuses; a conditional field (present_when, a DBC message's multiplexed signals: an IDL struct
// has no such member); a field name that is not a ROS 2 field name ([a-z][a-z0-9_]*, no "__", not
// ending in '_': DBC signals and LCM members are often CamelCase, and a renamed field would not be
// the field the channel's other tools know); a collection .msg cannot write (a sequence of arrays
// or sequences, an array of sequences).
//
// Pure: no I/O, never throws (but for memory). Any thread; called once per channel when the
// recorder's channel table is built, never per event.
#pragma once

#include <string>
#include <string_view>

#include "cosmic/channel_type.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

inline constexpr std::string_view kRos2MsgGeneratedPackage = "cosmic";

struct Ros2MsgSchema {
  std::string name;  // "pkg/msg/Name": the MCAP Schema record's name
  std::string text;  // the Schema record's data (encoding "ros2msg")
};

// The ROS 2 message definition of `type`, the type of the channel `channel_name`; else why not.
Result<Ros2MsgSchema> ros2_msg_schema(const ChannelType& type, std::string_view channel_name);

// Whether `name` is a ROS 2 field name, as rosidl_adapter and @foxglove/rosmsg check it.
bool valid_ros2_field_name(std::string_view name);

}  // namespace cosmic

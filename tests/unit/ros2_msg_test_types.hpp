// A channel type with every kind of field a ROS 2 message can carry (cosmic/ros2_msg_schema.hpp):
// shared by the unit test of its message definition (ros2_msg_schema_test.cpp) and by
// tests/mcap's CDR sample, which npm's @foxglove/rosmsg2-serialization decodes, so the definition
// pinned down by the unit test is the one a decoder we did not write reads the bytes with.
#pragma once

#include "schema_test_types.hpp"

namespace cosmic::ros2_msg_test {

// schema_test::every_kind() without its conditional fields (every scalar kind, enumerations of 8
// and 64 bits, a bounded string, arrays of floats and of arrays, bounded sequences of integers and
// of records, a nested record), and what it lacks: a 32-bit enumeration (an IDL enum in CDR), one
// that names OFF again (so only the first keeps its constants), a record nested two deep, an array
// of records, an array of strings and a sequence of bools.
inline ChannelType every_kind() {
  using namespace schema_test;
  using K = ScalarKind;
  ChannelType type = schema_test::every_kind();
  std::erase_if(type.fields, [](const TypeField& f) { return f.present_when.has_value(); });
  const ChannelType more = channel_type({
      field("direction", enumeration(K::int32, {{"FORWARD", 1}, {"REVERSE", -1}})),
      field("power", enumeration(K::uint8, {{"OFF", 0}, {"ON", 1}})),
      field("fix",
            record({field("origin", record({field("lat", scalar(K::float64)), field("lon", scalar(K::float64))})),
                    field("quality", scalar(K::uint8))})),
      field("corners", array(record({field("x", scalar(K::int16)),
                                     field("light", enumeration(K::uint8, {{"OFF", 0}, {"ON", 1}}))}),
                             2)),
      field("names", array(text(5), 2)),
      field("flags", sequence(scalar(K::boolean), 4)),
  });
  type.fields.insert(type.fields.end(), more.fields.begin(), more.fields.end());
  return type;
}

}  // namespace cosmic::ros2_msg_test

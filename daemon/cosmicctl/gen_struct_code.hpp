// The code of a typed channel's generated header that writes and reads its records in the compact
// layout (gen_struct.cpp declares the structs): per record, detail::write() and detail::read().
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"

namespace cosmicctl {

// What gen_struct.cpp named of one record: the struct (from the channel's namespace, e.g.
// "Event::Pose") and each field's member.
struct RecordCode {
  std::string qualified;
  std::vector<std::string> members;
};

// `write(compact::Writer&, const RECORD&)` and `read(compact::Reader&, RECORD&)` of one record;
// `path` is its place in the event for refusals ("" the event, "pose", "track[]").
std::string record_codec(const std::vector<cosmic::TypeField>& fields, const RecordCode& code, const std::string& path);

// "std::int16_t", "bool", "double", ...
std::string scalar_cpp_type(cosmic::ScalarKind kind);
// An int64 as a C++ literal (INT64_MIN written so it parses).
std::string integer_literal(std::int64_t value);
// "pose" + "x" -> "pose.x"; "" + "x" -> "x".
std::string path_of(const std::string& path, const std::string& name);

}  // namespace cosmicctl

// What the tests of the JSON event reader share (json_event_reader_test.cpp,
// json_event_refusal_test.cpp): a small type with a field of each kind, its canonical text, and
// helpers that write and read through cosmic::JsonRepresentation and cosmic::JsonEventReader.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/json_event_reader.hpp"
#include "cosmic/json_representation.hpp"
#include "schema_test_types.hpp"

namespace cosmic::json_event_test {

using Bytes = std::vector<std::uint8_t>;

// {speed: float32, gear: int8, count: uint64, state: enum uint8 {OFF=0, ON=1}, name: string<=8>,
//  xy: float64[2], track: sequence<int16, 3>, pose: {x: float64, y: float64}}
inline ChannelType tolerant_type() {
  using namespace schema_test;
  using K = ScalarKind;
  return channel_type({field("speed", scalar(K::float32)), field("gear", scalar(K::int8)),
                       field("count", scalar(K::uint64)),
                       field("state", enumeration(K::uint8, {{"OFF", 0}, {"ON", 1}})), field("name", text(8)),
                       field("xy", array(scalar(K::float64), 2)), field("track", sequence(scalar(K::int16), 3)),
                       field("pose", record({field("x", scalar(K::float64)), field("y", scalar(K::float64))}))});
}

// What write() writes for one event of tolerant_type().
inline constexpr std::string_view kTolerantCanonical =
    R"({"speed":1.5,"gear":-3,"count":9,"state":"ON","name":"hi","xy":[0.5,-1],"track":[7],"pose":{"x":1,"y":2}})";

// kTolerantCanonical with `part` replaced by `with`.
inline std::string tolerant_with(std::string_view part, std::string_view with) {
  std::string text(kTolerantCanonical);
  const std::size_t at = text.find(part);
  EXPECT_NE(at, std::string::npos) << part;
  if (at != std::string::npos) text.replace(at, part.size(), with);
  return text;
}

// tolerant_type()'s count field (after speed and gear).
inline std::uint64_t uint64_at(const Bytes& event) {
  std::uint64_t v = 0;
  if (event.size() >= 13) std::memcpy(&v, event.data() + 5, 8);
  return v;
}

inline std::string written_json(const JsonRepresentation& writer, const Bytes& event) {
  std::string out(writer.max_size(), '\0');
  const auto size = writer.write(event, std::span<char>(out.data(), out.size()));
  EXPECT_TRUE(size.has_value());
  out.resize(size.value_or(0));
  return out;
}

// The event read from `json`, or empty (with a failure naming the reason).
inline Bytes read_json(const ChannelType& type, std::string_view json) {
  const JsonEventReader reader{ChannelType(type)};
  Bytes out(reader.max_compact_size());
  const Result<std::size_t> read = reader.read(json, out);
  EXPECT_TRUE(read.ok()) << json << ": " << (read.ok() ? "" : read.error().text);
  out.resize(read.ok() ? read.value() : 0);
  return out;
}

// Why `json` is not an event of `type` (empty when it is one: a failure then).
inline std::string refusal_of(const ChannelType& type, std::string_view json) {
  const JsonEventReader reader{ChannelType(type)};
  Bytes out(reader.max_compact_size());
  const Result<std::size_t> read = reader.read(json, out);
  EXPECT_FALSE(read.ok()) << json << " was read";
  // The quiet form refuses exactly the same texts.
  EXPECT_FALSE(reader.read_unexplained(json, out).has_value()) << json;
  return read.ok() ? std::string() : read.error().text;
}

}  // namespace cosmic::json_event_test

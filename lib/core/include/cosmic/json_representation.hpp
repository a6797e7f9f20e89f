// A typed event as JSON (issue 35, "JSON, for tools"): one object per event,
//   {"SpeedFL": 12.34, "State": "Ajar", "Dtc": 17, "pose": {"x": 1.5}, "ranges": [0.5, 1]}
// fields in the type's order; numbers as the shortest text that reads back as the same double
// (a float32 as the double it exactly is; NaN and infinities, which JSON lacks, as null); bools as true and false; an
// enumeration as the name of its value (a value it does not name as the number); strings JSON-escaped, with every byte
// that is not part of valid UTF-8 as \ufffd; arrays and sequences as arrays; records as objects. A conditional field
// its selector does not select is left out. A unit of its own (its fuzz target: fuzz_json_events).
//
// Built once per type (at bind, on the control thread), then only read: write() runs on the
// forwarding threads into a caller's buffer, allocates nothing and never throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>

#include "cosmic/channel_type.hpp"

namespace cosmic {

class JsonRepresentation {
 public:
  explicit JsonRepresentation(ChannelType type);
  // Holds pointers into its own type: moved, never copied.
  JsonRepresentation(const JsonRepresentation&) = delete;
  JsonRepresentation& operator=(const JsonRepresentation&) = delete;
  JsonRepresentation(JsonRepresentation&&) = default;
  JsonRepresentation& operator=(JsonRepresentation&&) = default;

  // The most bytes write() needs for any event of the type.
  std::size_t max_size() const { return max_size_; }

  // One event in the compact layout (cosmic/compact_layout.hpp) as JSON in `out`: the bytes written,
  // or nullopt when `compact` is not one event of the type (cosmic::check_compact() says why) or
  // `out` is too small.
  std::optional<std::size_t> write(std::span<const std::uint8_t> compact, std::span<char> out) const;

 private:
  ChannelType type_;
  std::size_t max_size_ = 0;
  // A conditional field -> the index of its selector in the same record.
  std::unordered_map<const TypeField*, std::size_t> selectors_;
};

}  // namespace cosmic

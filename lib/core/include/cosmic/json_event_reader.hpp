// A typed event read from JSON into the compact layout (issue 37: replaying recordings, whose typed
// events are stored as JSON; tools publishing on a native LCM hop with `representation: json`). The
// exact inverse of cosmic::JsonRepresentation::write on everything it writes, and tolerant where
// another producer may differ (docs/typed-layout.md, "Reading JSON"):
//   - fields in any order, whitespace anywhere JSON allows it;
//   - an integer as a JSON integer or as a number with an integral value (2.0, 1e3) within its kind;
//   - a float from any JSON number (a float32 rounded to nearest), null as NaN (write() writes NaN
//     and infinities as null, so an infinity comes back as NaN); a number below the smallest double
//     as 0;
//   - an enumeration by the name of its value or by number (an unnamed number within the
//     underlying integer too, as write() writes one);
//   - a string as UTF-8 of at most its bound in bytes (escapes decoded; U+FFFD, which write() gives
//     an invalid byte, takes its three bytes);
//   - an array of exactly its length, a sequence of at most its bound, records as objects;
//   - a conditional field present exactly when its selector selects it: an unselected one must be
//     absent (null would be ambiguous: a selected float's null is NaN) and reads as zero bits.
// Refused, with a reason that names the field and the byte of the text: a missing field, an unknown
// or repeated one, a value beyond its kind, a too long string or sequence, an array of another
// length, a value of the wrong JSON type, invalid JSON or UTF-8, anything after the event, nesting
// deeper than kMaxJsonNesting, a text over max_text_size().
//
// A hand-written reader walking the text along the type: it writes the compact layout as it reads
// (a field given out of order is skipped and read when its turn comes) and allocates nothing but a
// refusal's reason. Built once per type (at bind, on the control thread), then only read: read()
// runs on any number of threads at once (a forwarding thread's ingress, a replay) and never throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>

#include "cosmic/channel_type.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// Arrays and objects nested deeper than this refuse a text (a type nests at most kMaxTypeDepth).
inline constexpr std::size_t kMaxJsonNesting = kMaxTypeDepth + 4;

class JsonEventReader {
 public:
  explicit JsonEventReader(ChannelType type);
  // Holds pointers into its own type: moved, never copied.
  JsonEventReader(const JsonEventReader&) = delete;
  JsonEventReader& operator=(const JsonEventReader&) = delete;
  JsonEventReader(JsonEventReader&&) = default;
  JsonEventReader& operator=(JsonEventReader&&) = default;

  // The longest text read: twice what write() writes at most, and 4 KiB more, for producers that
  // add whitespace or spell numbers longer (never more than 64 MiB).
  std::size_t max_text_size() const noexcept { return max_text_size_; }
  // The most bytes one event takes in the compact layout: `compact` of this size always suffices.
  std::size_t max_compact_size() const noexcept { return max_compact_size_; }

  // One event's JSON text into `compact`, the caller's buffer: the bytes of the event written there,
  // or why the text is not one event of the type ("pose.ranges[3] (byte 57): a number beyond
  // float32"); `compact` is then left in an unspecified state.
  Result<std::size_t> read(std::string_view json, std::span<std::uint8_t> compact) const;
  // The same without the reason: allocates nothing at all, for the forwarding path.
  std::optional<std::size_t> read_unexplained(std::string_view json, std::span<std::uint8_t> compact) const noexcept;

 private:
  ChannelType type_;
  std::size_t max_text_size_ = 0;
  std::size_t max_compact_size_ = 0;
  // A conditional field -> the index of its selector in the same record.
  std::unordered_map<const TypeField*, std::size_t> selectors_;
};

}  // namespace cosmic

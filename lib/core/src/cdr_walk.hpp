// The body of a CDR sample (what follows the 4-byte encapsulation header), walked over a channel's
// type: its largest size, a body into the compact layout and the compact layout into a body.
// Internal to CdrRepresentation (cosmic/cdr_representation.hpp), which picks the form from the
// encapsulation header; any thread, no allocation, no exceptions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/representation.hpp"

namespace cosmic::cdr_walk {

// Which of the plain encodings a body is in.
struct CdrForm {
  bool xcdr2 = false;
  bool delimited = false;  // XCDR2 of an appendable type: a DHEADER before every struct
  bool little_endian = true;
};

// The bytes that bring `at` to a multiple of `align`.
std::size_t padding(std::uint64_t at, std::size_t align);

// The largest body of a type (every string and sequence at its bound, alignment included).
std::uint64_t max_body_size(const std::vector<TypeField>& fields, CdrForm form);

struct Walked {
  std::size_t read = 0;     // bytes of the input the walk took
  std::size_t written = 0;  // bytes it wrote
  ConversionFault fault = ConversionFault::none;
};

// The record `fields` from `body` into `compact`. A body that goes on after the record is the
// caller's to judge (read < body.size()).
Walked read_body(const std::vector<TypeField>& fields, CdrForm form, std::span<const std::uint8_t> body,
                 std::span<std::uint8_t> compact) noexcept;
// The record from `compact` into a little-endian `body` (form.little_endian is ignored).
Walked write_body(const std::vector<TypeField>& fields, CdrForm form, std::span<const std::uint8_t> compact,
                  std::span<std::uint8_t> body) noexcept;

}  // namespace cosmic::cdr_walk

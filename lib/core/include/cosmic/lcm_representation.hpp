// A typed channel's hop on LCM in the struct's own encoding (issue 35, "each hop in its network's
// own form"): exactly the bytes lcm-gen's generated encode() writes and decode() reads, converted to
// and from the compact layout (cosmic/compact_layout.hpp) of the type lcm_channel_type() gives the
// struct (cosmic/lcm_types.hpp). A unit of its own (its fuzz target: fuzz_lcm_encoding).
//
// The LCM encoding: the struct's 8-byte fingerprint, big-endian, then its members in declaration
// order, nothing between them, nested structs without a fingerprint of their own:
//   int8_t..int64_t, float, double   big-endian (two's complement, IEEE 754)
//   byte                             1 byte
//   boolean                          1 byte: 0 false, anything else true (as lcm-gen's decoders read it)
//   string                           int32 length counting a terminating NUL, the bytes, the NUL
//   fixed dimension                  its length of elements
//   variable dimension               as many elements as its count member (an earlier integer member
//                                    of the same struct) holds: no length of its own on the wire
// The compact layout keeps the count member as a field and gives each sequence its own element
// count as well; the two must agree (from_compact refuses an event where they do not).
//
// Built once per binding (make(), on the control thread), then only read: to_compact() on the
// ingress thread that read the LCM message, from_compact() on the egress lane of the hop's segment,
// any number of threads at once. Neither allocates nor throws: both run a plan of steps worked out
// by make().
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/lcm_types.hpp"
#include "cosmic/representation.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

class LcmRepresentation final : public Representation {
 public:
  // The representation of `lcm_struct` (a struct of `file`, whose nested structs it finds there)
  // for `type`, which must have the struct's shape: lcm_channel_type()'s type for it, with any
  // bounds on strings and sequences (a configuration's max_length). The ChannelType alone does not
  // say which member counts which variable dimension; the struct does. Else why not: a member
  // whose field differs in name or kind, a nested struct missing or containing itself, a variable
  // dimension without an earlier integer count member, a conditional field (LCM has none), a type
  // check_type() refuses, or one whose messages could exceed 2^31 - 1 bytes (lcm-gen's C code
  // counts in int).
  static Result<LcmRepresentation> make(const LcmTypeFile& file, const LcmStruct& lcm_struct, const ChannelType& type);

  // "LCM exlcm.example_t".
  std::string describe() const override;
  std::size_t max_wire_size() const noexcept override { return max_wire_size_; }
  std::size_t max_compact_size() const noexcept override { return max_compact_size_; }
  // What every message of the struct starts with (lcm_fingerprint()).
  std::uint64_t fingerprint() const noexcept { return fingerprint_; }

  // One LCM message as one event. malformed: another fingerprint, the message cut short or longer
  // than its last member, a string's length below 1, above its bound + 1 or without its NUL, a
  // negative count member or one above its sequence's bound. A boolean other than 0 becomes 1 (every
  // LCM decoder reads it as true), so only then does the event not encode back to the same bytes.
  // A string's bytes are kept as they come, a NUL among them included.
  Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept override;
  // One event (check_compact() has accepted it) as one LCM message. malformed: a sequence whose
  // element count is not its count member's value, or a negative count member (no LCM decoder could
  // read the message back as the event: they take the count member's value as the length).
  Conversion from_compact(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) const noexcept override;

 private:
  // One instruction of the plan both conversions run, worked out by the Planner (both in
  // lcm_representation.cpp).
  struct Step {
    enum class Op : std::uint8_t {
      numbers,   // `length` numbers of `size` bytes each (per element of a sequence, if `counted_by`)
      booleans,  // `length` booleans (per element of a sequence, if `counted_by`)
      count,     // a count member of `size` bytes, its value kept in register `counts_into`
      string,    // a string of at most `bound` bytes
      begin,     // repeat the steps up to `jump` (its end): `length` times, or a sequence's count
      end,       // back to the step after `jump` (its begin) while repetitions remain
    };
    Op op = Op::numbers;
    std::uint8_t size = 0;
    std::uint16_t counted_by = kNotCounted;  // a sequence: the register holding its count member's value
    std::uint16_t counts_into = 0;
    std::uint32_t length = 0;
    std::uint32_t bound = 0;  // string: most bytes; sequence: most elements
    std::uint32_t jump = 0;
    static constexpr std::uint16_t kNotCounted = 0xFFFF;
  };
  class Planner;
  // Runs the plan, reading and writing through `walk` (one direction's reader and writer).
  template <typename Walk>
  ConversionFault run(Walk& walk) const noexcept;

  // Bounds on the plan, so that the conversions keep their state on the stack: count members whose
  // values are held at once (the struct's and those of the nested structs being read), and
  // repetitions nested in one another.
  static constexpr std::size_t kMaxCountRegisters = 64;
  static constexpr std::size_t kMaxRepeatDepth = 2 * kMaxTypeDepth;

  LcmRepresentation() = default;

  std::string name_;
  std::uint64_t fingerprint_ = 0;
  std::vector<Step> steps_;
  std::size_t max_wire_size_ = 0;
  std::size_t max_compact_size_ = 0;
};

}  // namespace cosmic

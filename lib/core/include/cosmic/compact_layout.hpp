// The compact layout of a typed channel's event (issue 35; docs/typed-layout.md): the one form the
// gateway itself gives a typed event's contents, between each network's own representation (a DBC
// frame, JSON, and next CDR and LCM). Fields in declaration order, nothing between them, every
// number little-endian:
//   bool           1 byte, 0 or 1
//   intN, uintN    N/8 bytes (two's complement for the signed)
//   float32/64     IEEE 754 binary32/binary64
//   enum           its underlying integer
//   string         uint32 byte count (at most the bound), then the bytes
//   array          its length of elements
//   sequence       uint32 element count (at most the bound), then the elements
//   record         its fields
// A conditional field (present_when) always has its place: zero bits (an empty string or sequence)
// while its selector does not select it.
//
// Pure functions on caller buffers: no allocation on the read and write paths, no I/O, never throw;
// any thread. A CompactLayout is built once per type (at bind) and only read afterwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// A scalar of any kind, in the member its kind uses: `integer` for signed kinds and enumerations of
// them, `unsigned_integer` for bool and unsigned kinds, `real` for floats.
struct ScalarValue {
  std::int64_t integer = 0;
  std::uint64_t unsigned_integer = 0;
  double real = 0.0;
  friend bool operator==(const ScalarValue&, const ScalarValue&) = default;
};

std::size_t scalar_size(ScalarKind kind);
ScalarValue read_scalar(ScalarKind kind, const std::uint8_t* at);
void write_scalar(ScalarKind kind, const ScalarValue& value, std::uint8_t* at);
// The value as a double (exact up to 2^53).
double scalar_as_double(ScalarKind kind, const ScalarValue& value);

// The size of a field type in the layout when it does not vary (no string or sequence inside).
std::optional<std::size_t> fixed_compact_size(const FieldType& type);
// The most bytes an event of the type takes (strings and sequences at their bounds).
std::size_t max_compact_size(const ChannelType& type);

// Whether `bytes` is exactly one event of `type` in the compact layout: every count within its
// bound, the bytes ending with the last field, bools 0 or 1. Enumerations may hold values they do
// not name (a DBC signal's raw values beyond its value table).
Result<void> check_compact(const ChannelType& type, std::span<const std::uint8_t> bytes);

// The top-level fields of a fixed-size type (a DBC message's, say) at their offsets, for codecs
// that read and write them directly.
class CompactLayout {
 public:
  struct Slot {
    std::size_t offset = 0;
    ScalarKind kind = ScalarKind::float64;  // a scalar's kind; an enumeration's underlying integer
    std::optional<std::size_t> selector;    // present_when: the index of the selecting field
    std::int64_t selected_by = 0;           // ... and the value that selects this one
  };

  // Every top-level field a scalar or an enumeration; else why not.
  static Result<CompactLayout> of_flat_record(const ChannelType& type);

  const std::vector<Slot>& slots() const { return slots_; }
  std::size_t size() const { return size_; }
  // Whether field `index` is present in `bytes` (an event of size()).
  bool present(std::size_t index, std::span<const std::uint8_t> bytes) const;

 private:
  std::vector<Slot> slots_;
  std::size_t size_ = 0;
};

}  // namespace cosmic

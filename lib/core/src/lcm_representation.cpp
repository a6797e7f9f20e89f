// A typed channel's LCM messages in the struct's own encoding (cosmic/lcm_representation.hpp).
// make() walks the struct's members beside the type's fields once and writes a flat plan: runs of
// numbers (a fixed array of doubles, or x, y, z in a row, is one step), strings, count members, and
// repetitions for arrays and sequences of strings and structs. Both conversions run that plan; they
// differ only in their Walk (which side they read and which they write).
#include "cosmic/lcm_representation.hpp"

#include <array>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>

#include "cosmic/compact_layout.hpp"

namespace cosmic {
namespace {

// lcm-gen's C code counts a message's bytes in int: a type whose message could be longer is refused.
constexpr std::uint64_t kLcmMaxMessageBytes = std::numeric_limits<std::int32_t>::max();
constexpr std::size_t kFingerprintBytes = 8;

std::optional<ScalarKind> lcm_number_kind(std::string_view type) {
  if (type == "int8_t") return ScalarKind::int8;
  if (type == "int16_t") return ScalarKind::int16;
  if (type == "int32_t") return ScalarKind::int32;
  if (type == "int64_t") return ScalarKind::int64;
  if (type == "byte") return ScalarKind::uint8;
  if (type == "float") return ScalarKind::float32;
  if (type == "double") return ScalarKind::float64;
  if (type == "boolean") return ScalarKind::boolean;
  return std::nullopt;
}

bool lcm_count_type(std::string_view type) {
  return type == "int8_t" || type == "int16_t" || type == "int32_t" || type == "int64_t";
}

std::uint64_t lcm_saturating_sum(std::uint64_t a, std::uint64_t b) {
  std::uint64_t sum = 0;
  return __builtin_add_overflow(a, b, &sum) ? std::numeric_limits<std::uint64_t>::max() : sum;
}

std::uint64_t lcm_saturating_product(std::uint64_t a, std::uint64_t b) {
  std::uint64_t product = 0;
  return __builtin_mul_overflow(a, b, &product) ? std::numeric_limits<std::uint64_t>::max() : product;
}

// The most bytes a value of the type takes in the LCM encoding (a sequence has no count of its own
// there: its count member is a field of its own).
std::uint64_t lcm_wire_bytes(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
      return scalar_size(type.scalar);
    case FieldType::Kind::string:
      return 4 + std::uint64_t{type.bound} + 1;
    case FieldType::Kind::array:
    case FieldType::Kind::sequence:
      return type.element.size() == 1 ? lcm_saturating_product(type.bound, lcm_wire_bytes(type.element[0])) : 0;
    case FieldType::Kind::record: {
      std::uint64_t sum = 0;
      for (const TypeField& f : type.fields) sum = lcm_saturating_sum(sum, lcm_wire_bytes(f.type));
      return sum;
    }
  }
  return 0;
}

// memcpy only with bytes to copy: an empty span's data() may be null, which memcpy may not see.
void copy_bytes(const std::uint8_t* from, std::uint8_t* to, std::size_t count) {
  if (count != 0) std::memcpy(to, from, count);
}

// Numbers from one byte order to the other: every number's bytes reversed.
void copy_byte_reversed(const std::uint8_t* from, std::uint8_t* to, std::size_t size, std::size_t count) {
  if (size == 1) {
    copy_bytes(from, to, count);
    return;
  }
  for (std::size_t i = 0; i < count; ++i, from += size, to += size) {
    for (std::size_t b = 0; b < size; ++b) to[b] = from[size - 1 - b];
  }
}

std::uint64_t load_big_endian(const std::uint8_t* at, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) value = (value << 8) | at[i];
  return value;
}

void store_big_endian(std::uint64_t value, std::uint8_t* at, std::size_t size) {
  for (std::size_t i = size; i-- > 0; value >>= 8) at[i] = static_cast<std::uint8_t>(value);
}

// Whether the top bit of a `size`-byte two's complement integer is set.
bool negative_integer(std::uint64_t bits, std::size_t size) { return (bits >> (8 * size - 1)) & 1; }

// The bytes still unread (Byte: const std::uint8_t) or unwritten (std::uint8_t) of one side of a
// conversion.
template <typename Byte>
class ByteCursor {
 public:
  explicit ByteCursor(std::span<Byte> bytes) : bytes_(bytes) {}

  bool has(std::uint64_t count) const { return bytes_.size() - at_ >= count; }
  Byte* take(std::size_t count) {
    Byte* here = bytes_.data() + at_;
    at_ += count;
    return here;
  }
  std::size_t used() const { return at_; }
  bool finished() const { return at_ == bytes_.size(); }

 private:
  std::span<Byte> bytes_;
  std::size_t at_ = 0;
};
using ReadCursor = ByteCursor<const std::uint8_t>;
using WriteCursor = ByteCursor<std::uint8_t>;

constexpr ConversionFault kFine = ConversionFault::none;
constexpr ConversionFault kMalformed = ConversionFault::malformed;
// Past the room max_compact_size() or max_wire_size() promised: the plan's sizes would be wrong.
constexpr ConversionFault kNoRoom = ConversionFault::too_small;

// to_compact's side: reads the LCM message (big-endian), writes the event (little-endian).
class LcmWireReader {
 public:
  LcmWireReader(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) : wire_(wire), compact_(compact) {}

  ConversionFault numbers(std::size_t size, std::uint64_t count) {
    const std::uint64_t bytes = count * size;  // count <= kMaxFlattenedScalars * bound: no overflow
    if (!wire_.has(bytes)) return kMalformed;
    if (!compact_.has(bytes)) return kNoRoom;
    copy_byte_reversed(wire_.take(bytes), compact_.take(bytes), size, count);
    return kFine;
  }

  // Every LCM decoder reads a boolean as an int8 and any value but 0 as true; the event holds 1.
  ConversionFault booleans(std::uint64_t count) {
    if (!wire_.has(count)) return kMalformed;
    if (!compact_.has(count)) return kNoRoom;
    const std::uint8_t* from = wire_.take(count);
    std::uint8_t* to = compact_.take(count);
    for (std::uint64_t i = 0; i < count; ++i) to[i] = from[i] != 0 ? 1 : 0;
    return kFine;
  }

  ConversionFault count(std::size_t size, std::uint64_t& value) {
    if (!wire_.has(size)) return kMalformed;
    if (!compact_.has(size)) return kNoRoom;
    const std::uint8_t* from = wire_.take(size);
    value = load_big_endian(from, size);
    if (negative_integer(value, size)) return kMalformed;
    copy_byte_reversed(from, compact_.take(size), size, 1);
    return kFine;
  }

  // int32 length counting the NUL, the bytes, the NUL -> uint32 byte count, the bytes.
  ConversionFault string(std::uint32_t bound) {
    if (!wire_.has(4)) return kMalformed;
    const std::uint64_t length = load_big_endian(wire_.take(4), 4);
    if (negative_integer(length, 4) || length < 1 || length - 1 > bound || !wire_.has(length)) return kMalformed;
    const std::uint8_t* text = wire_.take(length);
    if (text[length - 1] != 0) return kMalformed;
    if (!compact_.has(4 + length - 1)) return kNoRoom;
    store_little_endian_u32(static_cast<std::uint32_t>(length - 1), compact_.take(4));
    copy_bytes(text, compact_.take(length - 1), length - 1);
    return kFine;
  }

  // A sequence's elements are as many as its count member says; the event gets that count too.
  ConversionFault sequence(std::uint32_t bound, std::uint64_t count_member, std::uint32_t& elements) {
    if (count_member > bound) return kMalformed;
    if (!compact_.has(4)) return kNoRoom;
    elements = static_cast<std::uint32_t>(count_member);
    store_little_endian_u32(elements, compact_.take(4));
    return kFine;
  }

  const ReadCursor& wire() const { return wire_; }
  const WriteCursor& compact() const { return compact_; }

 private:
  static void store_little_endian_u32(std::uint32_t value, std::uint8_t* at) {
    for (int i = 0; i < 4; ++i, value >>= 8) at[i] = static_cast<std::uint8_t>(value);
  }

  ReadCursor wire_;
  WriteCursor compact_;
};

// from_compact's side: reads the event (little-endian), writes the LCM message (big-endian).
class LcmWireWriter {
 public:
  LcmWireWriter(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) : compact_(compact), wire_(wire) {}

  ConversionFault numbers(std::size_t size, std::uint64_t count) {
    const std::uint64_t bytes = count * size;
    if (!compact_.has(bytes)) return kMalformed;
    if (!wire_.has(bytes)) return kNoRoom;
    copy_byte_reversed(compact_.take(bytes), wire_.take(bytes), size, count);
    return kFine;
  }

  // check_compact() has seen to 0 or 1; anything else is written as true, 1, all the same.
  ConversionFault booleans(std::uint64_t count) {
    if (!compact_.has(count)) return kMalformed;
    if (!wire_.has(count)) return kNoRoom;
    const std::uint8_t* from = compact_.take(count);
    std::uint8_t* to = wire_.take(count);
    for (std::uint64_t i = 0; i < count; ++i) to[i] = from[i] != 0 ? 1 : 0;
    return kFine;
  }

  ConversionFault count(std::size_t size, std::uint64_t& value) {
    if (!compact_.has(size)) return kMalformed;
    if (!wire_.has(size)) return kNoRoom;
    std::uint8_t* to = wire_.take(size);
    copy_byte_reversed(compact_.take(size), to, size, 1);
    value = load_big_endian(to, size);
    return negative_integer(value, size) ? kMalformed : kFine;
  }

  ConversionFault string(std::uint32_t bound) {
    if (!compact_.has(4)) return kMalformed;
    const std::uint32_t length = load_little_endian_u32(compact_.take(4));
    if (length > bound || !compact_.has(length)) return kMalformed;
    if (!wire_.has(4 + std::uint64_t{length} + 1)) return kNoRoom;
    store_big_endian(std::uint64_t{length} + 1, wire_.take(4), 4);
    copy_bytes(compact_.take(length), wire_.take(length), length);
    *wire_.take(1) = 0;
    return kFine;
  }

  // The event's count of a sequence must be its count member's value: LCM sends only the latter, so
  // any other count would reach LCM's readers as a different event (or a message they cannot read).
  ConversionFault sequence(std::uint32_t bound, std::uint64_t count_member, std::uint32_t& elements) {
    if (!compact_.has(4)) return kMalformed;
    elements = load_little_endian_u32(compact_.take(4));
    return elements > bound || elements != count_member ? kMalformed : kFine;
  }

  const WriteCursor& wire() const { return wire_; }
  const ReadCursor& compact() const { return compact_; }

 private:
  static std::uint32_t load_little_endian_u32(const std::uint8_t* at) {
    return std::uint32_t{at[0]} | std::uint32_t{at[1]} << 8 | std::uint32_t{at[2]} << 16 | std::uint32_t{at[3]} << 24;
  }

  ReadCursor compact_;
  WriteCursor wire_;
};

}  // namespace

// Walks a struct's members beside the type's fields, checking that they agree, and writes the plan.
class LcmRepresentation::Planner {
 public:
  Planner(const LcmTypeFile& file, std::vector<Step>& steps) : file_(file), steps_(steps) {}

  // Where a record is read: its first free count register, repetitions around it, structs around
  // it, and its name for errors.
  struct Scope {
    std::size_t first_register = 0;
    std::size_t repeats = 0;
    std::size_t nesting = 0;
    std::string where;
  };

  Result<void> record(const LcmStruct& s, const std::vector<TypeField>& fields, const Scope& scope) {
    if (fields.size() != s.members.size()) {
      return Error{scope.where + ": the type has " + std::to_string(fields.size()) + " fields, struct " +
                   s.full_name() + " " + std::to_string(s.members.size()) + " members"};
    }
    std::vector<std::uint16_t> registers(s.members.size(), Step::kNotCounted);
    auto next_register = assign_registers(s, scope, registers);
    if (!next_register) return std::move(next_register).error();
    Scope inner = scope;
    inner.first_register = next_register.value();
    for (std::size_t i = 0; i < s.members.size(); ++i) {
      const LcmMember& m = s.members[i];
      const TypeField& f = fields[i];
      inner.where = scope.where + "." + m.name;
      if (f.name != m.name) return Error{inner.where + ": the type's field here is " + f.name};
      if (f.present_when) return Error{inner.where + ": a conditional field, which LCM has not"};
      const Member member{s, i, registers};
      auto planned = registers[i] != Step::kNotCounted ? count_member(member, f.type, inner.where)
                                                       : value(member, f.type, 0, inner);
      if (!planned) return planned;
    }
    return {};
  }

 private:
  struct Member {
    const LcmStruct& s;
    std::size_t index;
    const std::vector<std::uint16_t>& registers;  // a count member's register, by member index
    const LcmMember& lcm() const { return s.members[index]; }
  };

  // Gives each count member of the struct a register (the struct's own, above those of the structs
  // around it, reused by its siblings): the first register free after them, or why there is none.
  static Result<std::size_t> assign_registers(const LcmStruct& s, const Scope& scope,
                                              std::vector<std::uint16_t>& registers) {
    std::size_t next = scope.first_register;
    for (std::size_t i = 0; i < s.members.size(); ++i) {
      for (const LcmDimension& d : s.members[i].dimensions) {
        if (!d.variable) continue;
        std::size_t c = 0;
        while (c < i && s.members[c].name != d.size) ++c;
        if (c == i || !lcm_count_type(s.members[c].type) || !s.members[c].dimensions.empty()) {
          return Error{scope.where + "." + s.members[i].name + ": its size " + d.size +
                       " is not an integer member declared before it"};
        }
        if (registers[c] != Step::kNotCounted) continue;
        if (next >= kMaxCountRegisters) {
          return Error{scope.where + ": more than " + std::to_string(kMaxCountRegisters) +
                       " count members of variable-length arrays at once"};
        }
        registers[c] = static_cast<std::uint16_t>(next++);
      }
    }
    return next;
  }

  Result<void> count_member(const Member& member, const FieldType& type, const std::string& where) {
    const auto kind = lcm_number_kind(member.lcm().type);
    if (!scalar_matches(type, kind)) return mismatch(where, member.lcm().type, type);
    Step step;
    step.op = Step::Op::count;
    step.size = static_cast<std::uint8_t>(scalar_size(*kind));
    step.counts_into = member.registers[member.index];
    steps_.push_back(step);
    return {};
  }

  // The member's value from its dimension `dimension` inwards (all of them: its element).
  Result<void> value(const Member& member, const FieldType& type, std::size_t dimension, const Scope& scope) {
    const LcmMember& m = member.lcm();
    if (dimension == m.dimensions.size()) return element(m, type, scope);
    const LcmDimension& d = m.dimensions[dimension];
    const auto length = fixed_length(d);
    const bool shaped = d.variable ? type.kind == FieldType::Kind::sequence
                                   : type.kind == FieldType::Kind::array && length && *length == type.bound;
    if (!shaped || type.element.size() != 1) {
      return Error{scope.where + ": dimension [" + d.size + "] of the struct's member, " + cosmic::describe(type) +
                   " in the type"};
    }
    std::uint16_t counted_by = Step::kNotCounted;
    if (d.variable) counted_by = member.registers[count_index(member.s, member.index, d)];
    if (const auto run = plain_run(m, type.element[0], dimension + 1)) {
      emit_scalars(run->kind, run->per_element * (d.variable ? 1 : type.bound), counted_by, type.bound);
      return {};
    }
    if (scope.repeats >= kMaxRepeatDepth) return Error{scope.where + ": arrays nested too deep"};
    const std::size_t begin = steps_.size();
    Step step;
    step.op = Step::Op::begin;
    step.counted_by = counted_by;
    step.length = d.variable ? 0 : type.bound;
    step.bound = type.bound;
    steps_.push_back(step);
    Scope inner = scope;
    ++inner.repeats;
    if (auto planned = value(member, type.element[0], dimension + 1, inner); !planned) return planned;
    step = Step{};
    step.op = Step::Op::end;
    step.jump = static_cast<std::uint32_t>(begin);
    steps_[begin].jump = static_cast<std::uint32_t>(steps_.size());
    steps_.push_back(step);
    return {};
  }

  // A primitive, a string, or a nested struct (without a fingerprint of its own).
  Result<void> element(const LcmMember& m, const FieldType& type, const Scope& scope) {
    if (m.type == "string") {
      if (type.kind != FieldType::Kind::string) return mismatch(scope.where, m.type, type);
      Step step;
      step.op = Step::Op::string;
      step.bound = type.bound;
      steps_.push_back(step);
      return {};
    }
    if (lcm_is_primitive(m.type)) {
      const auto kind = lcm_number_kind(m.type);
      if (!scalar_matches(type, kind)) return mismatch(scope.where, m.type, type);
      emit_scalars(*kind, 1, Step::kNotCounted, 0);
      return {};
    }
    const LcmStruct* nested = file_.find(m.type);
    if (nested == nullptr) return Error{scope.where + ": struct " + m.type + " is not in the file"};
    if (type.kind != FieldType::Kind::record) return mismatch(scope.where, m.type, type);
    if (scope.nesting + 1 >= kMaxTypeDepth) return Error{scope.where + ": structs nested too deep"};
    Scope inner = scope;
    ++inner.nesting;
    return record(*nested, type.fields, inner);
  }

  struct Run {
    ScalarKind kind;
    std::uint64_t per_element;
  };
  // When the member's dimensions from `dimension` on are all fixed and its type a primitive number:
  // the numbers one element of the enclosing dimension holds, all in a row.
  static std::optional<Run> plain_run(const LcmMember& m, const FieldType& element, std::size_t dimension) {
    const FieldType* type = &element;
    std::uint64_t per_element = 1;
    for (; dimension < m.dimensions.size(); ++dimension) {
      const auto length = fixed_length(m.dimensions[dimension]);
      if (!length || type->kind != FieldType::Kind::array || *length != type->bound || type->element.size() != 1) {
        return std::nullopt;
      }
      per_element *= type->bound;
      type = &type->element[0];
    }
    const auto kind = lcm_number_kind(m.type);
    if (!scalar_matches(*type, kind)) return std::nullopt;
    return Run{*kind, per_element};
  }

  // Numbers in a row: one step, or more of the step before when that one is numbers of the same
  // size too (x, y, z: 24 bytes reversed eight at a time).
  void emit_scalars(ScalarKind kind, std::uint64_t length, std::uint16_t counted_by, std::uint32_t bound) {
    Step step;
    step.op = kind == ScalarKind::boolean ? Step::Op::booleans : Step::Op::numbers;
    step.size = static_cast<std::uint8_t>(scalar_size(kind));
    step.counted_by = counted_by;
    step.length = static_cast<std::uint32_t>(length);  // at most kMaxFlattenedScalars (check_type)
    step.bound = counted_by == Step::kNotCounted ? 0 : bound;
    if (!steps_.empty() && counted_by == Step::kNotCounted) {
      Step& last = steps_.back();
      if (last.op == step.op && last.size == step.size && last.counted_by == Step::kNotCounted) {
        last.length += step.length;
        return;
      }
    }
    steps_.push_back(step);
  }

  static bool scalar_matches(const FieldType& type, std::optional<ScalarKind> kind) {
    const bool scalar = type.kind == FieldType::Kind::scalar ||
                        (type.kind == FieldType::Kind::enumeration && kind != ScalarKind::boolean);
    return kind && scalar && type.scalar == *kind;
  }

  static std::optional<std::uint32_t> fixed_length(const LcmDimension& d) {
    std::uint32_t length = 0;
    const char* end = d.size.data() + d.size.size();
    const auto [rest, error] = std::from_chars(d.size.data(), end, length);
    if (d.variable || error != std::errc{} || rest != end) return std::nullopt;
    return length;
  }

  // The index of the count member of variable dimension `d` (assign_registers found it).
  static std::size_t count_index(const LcmStruct& s, std::size_t member, const LcmDimension& d) {
    std::size_t c = 0;
    while (c < member && s.members[c].name != d.size) ++c;
    return c;
  }

  static Error mismatch(const std::string& where, const std::string& lcm_type, const FieldType& type) {
    return Error{where + ": " + lcm_type + " in the struct, " + cosmic::describe(type) + " in the type"};
  }

  const LcmTypeFile& file_;
  std::vector<Step>& steps_;
};

Result<LcmRepresentation> LcmRepresentation::make(const LcmTypeFile& file, const LcmStruct& lcm_struct,
                                                  const ChannelType& type) {
  const std::string name = lcm_struct.full_name();
  const auto fingerprint = lcm_fingerprint(file, lcm_struct);
  if (!fingerprint) return Error{"LCM struct " + name + " nests a struct missing from its file or itself"};
  if (const auto problems = check_type(type); !problems.empty()) {
    return Error{"LCM " + name + ": " + problems.front().where + ": " + problems.front().what};
  }
  LcmRepresentation representation;
  Planner planner(file, representation.steps_);
  if (auto planned = planner.record(lcm_struct, type.fields, Planner::Scope{0, 0, 0, name}); !planned) {
    return Error{"LCM " + std::move(planned).error().text};
  }
  std::uint64_t wire = kFingerprintBytes;
  for (const TypeField& f : type.fields) wire = lcm_saturating_sum(wire, lcm_wire_bytes(f.type));
  const std::uint64_t compact = cosmic::max_compact_size(type);
  if (wire > kLcmMaxMessageBytes || compact > kLcmMaxMessageBytes) {
    return Error{"LCM " + name + ": its messages could be longer than 2^31 - 1 bytes (bound its strings and arrays)"};
  }
  representation.name_ = name;
  representation.fingerprint_ = *fingerprint;
  representation.max_wire_size_ = static_cast<std::size_t>(wire);
  representation.max_compact_size_ = static_cast<std::size_t>(compact);
  return representation;
}

std::string LcmRepresentation::describe() const { return "LCM " + name_; }

template <typename Walk>
ConversionFault LcmRepresentation::run(Walk& walk) const noexcept {
  std::array<std::uint64_t, kMaxCountRegisters> counts{};  // count members' values, by register
  std::array<std::uint32_t, kMaxRepeatDepth> remaining{};  // repetitions left, innermost last
  std::size_t depth = 0;
  std::size_t at = 0;
  while (at < steps_.size()) {
    const Step& step = steps_[at];
    std::uint32_t elements = 1;
    if (step.counted_by != Step::kNotCounted) {
      if (const auto fault = walk.sequence(step.bound, counts[step.counted_by], elements); fault != kFine) return fault;
    }
    ConversionFault fault = kFine;
    switch (step.op) {
      case Step::Op::numbers:
        fault = walk.numbers(step.size, std::uint64_t{elements} * step.length);
        break;
      case Step::Op::booleans:
        fault = walk.booleans(std::uint64_t{elements} * step.length);
        break;
      case Step::Op::count:
        fault = walk.count(step.size, counts[step.counts_into]);
        break;
      case Step::Op::string:
        fault = walk.string(step.bound);
        break;
      case Step::Op::begin: {
        const std::uint32_t times = step.counted_by != Step::kNotCounted ? elements : step.length;
        if (times == 0) {
          at = step.jump + 1;
          continue;
        }
        remaining[depth++] = times;
        break;
      }
      case Step::Op::end:
        if (--remaining[depth - 1] > 0) {
          at = step.jump + 1;
          continue;
        }
        --depth;
        break;
    }
    if (fault != kFine) return fault;
    ++at;
  }
  return kFine;
}

Conversion LcmRepresentation::to_compact(std::span<const std::uint8_t> wire,
                                         std::span<std::uint8_t> compact) const noexcept {
  if (compact.size() < max_compact_size_) return Conversion{0, ConversionFault::too_small, 0};
  if (wire.size() < kFingerprintBytes || load_big_endian(wire.data(), kFingerprintBytes) != fingerprint_) {
    return Conversion{0, kMalformed, 0};
  }
  LcmWireReader reader(wire.subspan(kFingerprintBytes), compact);
  if (const auto fault = run(reader); fault != kFine) return Conversion{0, fault, 0};
  if (!reader.wire().finished()) return Conversion{0, kMalformed, 0};  // bytes after the last member
  return Conversion{reader.compact().used(), kFine, 0};
}

Conversion LcmRepresentation::from_compact(std::span<const std::uint8_t> compact,
                                           std::span<std::uint8_t> wire) const noexcept {
  if (wire.size() < max_wire_size_) return Conversion{0, ConversionFault::too_small, 0};
  store_big_endian(fingerprint_, wire.data(), kFingerprintBytes);
  LcmWireWriter writer(compact, wire.subspan(kFingerprintBytes));
  if (const auto fault = run(writer); fault != kFine) return Conversion{0, fault, 0};
  if (!writer.compact().finished()) return Conversion{0, kMalformed, 0};  // bytes after the last field
  return Conversion{kFingerprintBytes + writer.wire().used(), kFine, 0};
}

}  // namespace cosmic

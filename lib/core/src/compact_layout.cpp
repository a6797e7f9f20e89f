// The compact layout of a typed event (cosmic/compact_layout.hpp).
#include "cosmic/compact_layout.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <string>

namespace cosmic {
namespace {

std::uint64_t read_little_endian(const std::uint8_t* at, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) value |= std::uint64_t{at[i]} << (8 * i);
  return value;
}

void write_little_endian(std::uint64_t value, std::uint8_t* at, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) at[i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::int64_t sign_extend(std::uint64_t bits, std::size_t size) {
  if (size >= 8) return static_cast<std::int64_t>(bits);
  const std::uint64_t sign = std::uint64_t{1} << (8 * size - 1);
  return static_cast<std::int64_t>((bits ^ sign) - sign);
}

// Walks one value of a type through the bytes, checking as it goes. The place of a problem
// ("pose.ranges[3]") is kept as a stack of names and indexes and spelt out only for an error, so a
// sound event costs no allocation.
class CompactChecker {
 public:
  explicit CompactChecker(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  Result<void> record(const std::vector<TypeField>& fields) {
    for (const TypeField& f : fields) {
      if (!push(&f.name, 0)) return Error{where() + ": nested too deep"};
      auto checked = value(f.type);
      --depth_;
      if (!checked) return checked;
    }
    return {};
  }

  Result<void> finish() const {
    if (at_ == bytes_.size()) return {};
    return Error{"the event has " + std::to_string(bytes_.size() - at_) + " bytes after its last field"};
  }

 private:
  struct Step {
    const std::string* name = nullptr;  // a field, or nullptr for an element at `index`
    std::size_t index = 0;
  };

  bool push(const std::string* name, std::size_t index) {
    if (depth_ >= path_.size()) return false;
    path_[depth_++] = Step{name, index};
    return true;
  }

  std::string where() const {
    std::string out;
    for (std::size_t i = 0; i < depth_; ++i) {
      if (path_[i].name != nullptr) {
        out += (out.empty() ? "" : ".") + *path_[i].name;
      } else {
        out += "[" + std::to_string(path_[i].index) + "]";
      }
    }
    return out.empty() ? "the event" : out;
  }

  Result<void> value(const FieldType& type) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        return scalar(type.scalar);
      case FieldType::Kind::string: {
        const auto count = counted(type.bound, "bytes");
        if (!count) return count.error();
        return take(count.value());
      }
      case FieldType::Kind::array:
        return elements(type, type.bound);
      case FieldType::Kind::sequence: {
        const auto count = counted(type.bound, "elements");
        if (!count) return count.error();
        return elements(type, count.value());
      }
      case FieldType::Kind::record:
        return record(type.fields);
    }
    return {};
  }

  Result<void> scalar(ScalarKind kind) {
    if (auto room = take(scalar_size(kind)); !room) return room;
    if (kind == ScalarKind::boolean && bytes_[at_ - 1] > 1) {
      return Error{where() + ": a bool is 0 or 1, not " + std::to_string(bytes_[at_ - 1])};
    }
    return {};
  }

  Result<void> elements(const FieldType& type, std::size_t count) {
    if (type.element.size() != 1) return Error{where() + ": no element type"};
    const FieldType& element = type.element[0];
    const auto fixed = fixed_compact_size(element);
    const bool plain = element.kind == FieldType::Kind::scalar && element.scalar != ScalarKind::boolean;
    if (fixed && (plain || element.kind == FieldType::Kind::enumeration)) return take(*fixed * count);
    for (std::size_t i = 0; i < count; ++i) {
      if (!push(nullptr, i)) return Error{where() + ": nested too deep"};
      auto checked = value(element);
      --depth_;
      if (!checked) return checked;
    }
    return {};
  }

  Result<std::size_t> counted(std::uint32_t bound, const char* what) {
    if (auto room = take(4); !room) return room.error();
    const auto count = static_cast<std::size_t>(read_little_endian(&bytes_[at_ - 4], 4));
    if (count > bound) {
      return Error{where() + ": " + std::to_string(count) + " " + what + ", more than its bound " +
                   std::to_string(bound)};
    }
    return count;
  }

  Result<void> take(std::size_t size) {
    if (bytes_.size() - at_ < size) return Error{where() + ": the event ends inside it"};
    at_ += size;
    return {};
  }

  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
  std::array<Step, 2 * kMaxTypeDepth + 2> path_{};  // a field and an element index per level
  std::size_t depth_ = 0;
};

}  // namespace

std::size_t scalar_size(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::boolean:
    case ScalarKind::int8:
    case ScalarKind::uint8:
      return 1;
    case ScalarKind::int16:
    case ScalarKind::uint16:
      return 2;
    case ScalarKind::int32:
    case ScalarKind::uint32:
    case ScalarKind::float32:
      return 4;
    case ScalarKind::int64:
    case ScalarKind::uint64:
    case ScalarKind::float64:
      return 8;
  }
  return 8;
}

ScalarValue read_scalar(ScalarKind kind, const std::uint8_t* at) {
  const std::size_t size = scalar_size(kind);
  const std::uint64_t bits = read_little_endian(at, size);
  ScalarValue value;
  if (kind == ScalarKind::float32) {
    value.real = std::bit_cast<float>(static_cast<std::uint32_t>(bits));
  } else if (kind == ScalarKind::float64) {
    value.real = std::bit_cast<double>(bits);
  } else if (is_signed_integer(kind)) {
    value.integer = sign_extend(bits, size);
  } else {
    value.unsigned_integer = bits;
  }
  return value;
}

void write_scalar(ScalarKind kind, const ScalarValue& value, std::uint8_t* at) {
  std::uint64_t bits = 0;
  if (kind == ScalarKind::float32) {
    bits = std::bit_cast<std::uint32_t>(static_cast<float>(value.real));
  } else if (kind == ScalarKind::float64) {
    bits = std::bit_cast<std::uint64_t>(value.real);
  } else if (is_signed_integer(kind)) {
    bits = static_cast<std::uint64_t>(value.integer);
  } else {
    bits = value.unsigned_integer;
  }
  write_little_endian(bits, at, scalar_size(kind));
}

double scalar_as_double(ScalarKind kind, const ScalarValue& value) {
  if (kind == ScalarKind::float32 || kind == ScalarKind::float64) return value.real;
  if (is_signed_integer(kind)) return static_cast<double>(value.integer);
  return static_cast<double>(value.unsigned_integer);
}

std::optional<std::size_t> fixed_compact_size(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
      return scalar_size(type.scalar);
    case FieldType::Kind::string:
    case FieldType::Kind::sequence:
      return std::nullopt;
    case FieldType::Kind::array: {
      if (type.element.size() != 1) return std::nullopt;
      const auto element = fixed_compact_size(type.element[0]);
      if (!element) return std::nullopt;
      return *element * type.bound;
    }
    case FieldType::Kind::record: {
      std::size_t sum = 0;
      for (const TypeField& f : type.fields) {
        const auto size = fixed_compact_size(f.type);
        if (!size) return std::nullopt;
        sum += *size;
      }
      return sum;
    }
  }
  return std::nullopt;
}

namespace {

std::size_t max_size(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
      return scalar_size(type.scalar);
    case FieldType::Kind::string:
      return 4 + std::size_t{type.bound};
    case FieldType::Kind::array:
      return type.element.size() == 1 ? max_size(type.element[0]) * type.bound : 0;
    case FieldType::Kind::sequence:
      return 4 + (type.element.size() == 1 ? max_size(type.element[0]) * type.bound : 0);
    case FieldType::Kind::record: {
      std::size_t sum = 0;
      for (const TypeField& f : type.fields) sum += max_size(f.type);
      return sum;
    }
  }
  return 0;
}

}  // namespace

std::size_t max_compact_size(const ChannelType& type) {
  std::size_t sum = 0;
  for (const TypeField& f : type.fields) sum += max_size(f.type);
  return sum;
}

Result<void> check_compact(const ChannelType& type, std::span<const std::uint8_t> bytes) {
  CompactChecker checker(bytes);
  if (auto checked = checker.record(type.fields); !checked) return checked;
  return checker.finish();
}

Result<CompactLayout> CompactLayout::of_flat_record(const ChannelType& type) {
  CompactLayout layout;
  for (const TypeField& f : type.fields) {
    if (f.type.kind != FieldType::Kind::scalar && f.type.kind != FieldType::Kind::enumeration) {
      return Error{"field " + f.name + " is " + describe(f.type) + ", not a scalar or an enumeration"};
    }
    Slot slot;
    slot.offset = layout.size_;
    slot.kind = f.type.scalar;
    if (f.present_when) {
      const auto selector = std::find_if(type.fields.begin(), type.fields.end(),
                                         [&](const TypeField& s) { return s.name == f.present_when->selector; });
      if (selector == type.fields.end()) return Error{"field " + f.name + ": no selector " + f.present_when->selector};
      slot.selector = static_cast<std::size_t>(selector - type.fields.begin());
      slot.selected_by = f.present_when->value;
    }
    layout.slots_.push_back(slot);
    layout.size_ += scalar_size(slot.kind);
  }
  return layout;
}

bool CompactLayout::present(std::size_t index, std::span<const std::uint8_t> bytes) const {
  const Slot& slot = slots_[index];
  if (!slot.selector) return true;
  const Slot& selector = slots_[*slot.selector];
  if (bytes.size() < selector.offset + scalar_size(selector.kind)) return false;
  const ScalarValue value = read_scalar(selector.kind, bytes.data() + selector.offset);
  if (is_signed_integer(selector.kind)) return value.integer == slot.selected_by;
  return slot.selected_by >= 0 && value.unsigned_integer == static_cast<std::uint64_t>(slot.selected_by);
}

}  // namespace cosmic

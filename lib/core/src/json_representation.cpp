// A typed event as JSON (cosmic/json_representation.hpp). The event is checked whole first
// (check_compact), so the writer below reads without bounds checks of its own and only watches the
// output's room.
#include "cosmic/json_representation.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "cosmic/compact_layout.hpp"
#include "json_text.hpp"

namespace cosmic {
namespace json_text {
namespace {

std::size_t max_value_size(const FieldType& type);

void index_selectors_of(const FieldType& type, Selectors& out) {
  if (type.kind == FieldType::Kind::record) index_selectors(type.fields, out);
  for (const FieldType& element : type.element) index_selectors_of(element, out);
}

}  // namespace

constexpr std::size_t kNumberText = 32;  // the longest number to_chars writes, with room

std::size_t max_record_size(const std::vector<TypeField>& fields) {
  std::size_t sum = 2;                                                                  // {}
  for (const TypeField& f : fields) sum += f.name.size() + 4 + max_value_size(f.type);  // "name": and a comma
  return sum;
}

namespace {

std::size_t max_value_size(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
      return kNumberText;
    case FieldType::Kind::enumeration: {
      std::size_t longest = kNumberText;
      for (const EnumValue& v : type.values) longest = std::max(longest, v.name.size() + 2);
      return longest;
    }
    case FieldType::Kind::string:
      return 2 + std::size_t{type.bound} * 6;  // every byte \ufffd or \u00XX at worst
    case FieldType::Kind::array:
    case FieldType::Kind::sequence:
      return 2 + (type.element.size() == 1 ? (max_value_size(type.element[0]) + 1) * type.bound : 0);
    case FieldType::Kind::record:
      return max_record_size(type.fields);
  }
  return 0;
}

}  // namespace

void index_selectors(const std::vector<TypeField>& fields, Selectors& out) {
  for (const TypeField& f : fields) {
    if (f.present_when) {
      const auto selector = std::find_if(fields.begin(), fields.end(),
                                         [&](const TypeField& s) { return s.name == f.present_when->selector; });
      if (selector != fields.end()) out[&f] = static_cast<std::size_t>(selector - fields.begin());
    }
    index_selectors_of(f.type, out);
  }
}

// The length of the valid UTF-8 sequence starting at `text` (1..4), or 0 when it is not one.
std::size_t utf8_sequence(std::string_view text) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char first = byte(0);
  std::size_t length = 0;
  std::uint32_t code = 0;
  if (first < 0x80) return 1;
  if (first >= 0xC2 && first <= 0xDF) {
    length = 2;
    code = first & 0x1Fu;
  } else if (first >= 0xE0 && first <= 0xEF) {
    length = 3;
    code = first & 0x0Fu;
  } else if (first >= 0xF0 && first <= 0xF4) {
    length = 4;
    code = first & 0x07u;
  } else {
    return 0;
  }
  if (text.size() < length) return 0;
  for (std::size_t i = 1; i < length; ++i) {
    if ((byte(i) & 0xC0u) != 0x80u) return 0;
    code = (code << 6) | (byte(i) & 0x3Fu);
  }
  const bool overlong = (length == 3 && code < 0x800) || (length == 4 && code < 0x10000);
  const bool surrogate = code >= 0xD800 && code <= 0xDFFF;
  return overlong || surrogate || code > 0x10FFFF ? 0 : length;
}

}  // namespace json_text

namespace {

using json_text::kNumberText;
using json_text::utf8_sequence;

class JsonWriter {
 public:
  JsonWriter(std::span<const std::uint8_t> compact, std::span<char> out,
             const std::unordered_map<const TypeField*, std::size_t>& selectors)
      : in_(compact), out_(out), selectors_(selectors) {}

  bool record(const std::vector<TypeField>& fields) {
    // The integer value of each field read so far, for the conditional fields that follow. Not
    // zero-filled (a sequence of records would fill 2 KiB per element): an entry is read only for a
    // selector, an integer field before the field it selects (check_type), which value() has set.
    std::array<std::int64_t, kMaxRecordFields> values;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    if (!put("{")) return false;
    bool first = true;
    for (std::size_t i = 0; i < fields.size() && i < values.size(); ++i) {
      const TypeField& f = fields[i];
      const bool shown = !f.present_when || selected(f, values);
      if (shown) {
        if (!put(first ? "\"" : ",\"") || !put(f.name) || !put("\":")) return false;
        first = false;
      }
      if (!value(f.type, shown, values[i])) return false;  // read past, written only when shown
    }
    return put("}");
  }

  std::size_t written() const { return out_at_; }

 private:
  bool selected(const TypeField& f, const std::array<std::int64_t, kMaxRecordFields>& values) const {
    const auto selector = selectors_.find(&f);
    return selector != selectors_.end() && values[selector->second] == f.present_when->value;
  }

  // Reads one value (and writes it when `shown`); an integer's value goes to `integer`.
  bool value(const FieldType& type, bool shown, std::int64_t& integer) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
        return scalar(type.scalar, shown, integer);
      case FieldType::Kind::enumeration:
        return enumeration(type, shown, integer);
      case FieldType::Kind::string:
        return string(shown);
      case FieldType::Kind::array:
        return elements(type.element[0], type.bound, shown);
      case FieldType::Kind::sequence:
        return elements(type.element[0], count(), shown);
      case FieldType::Kind::record:
        return shown ? record(type.fields) : skip_record(type.fields);
    }
    return false;
  }

  bool skip_record(const std::vector<TypeField>& fields) {
    std::int64_t ignored = 0;
    for (const TypeField& f : fields) {
      if (!value(f.type, false, ignored)) return false;
    }
    return true;
  }

  bool scalar(ScalarKind kind, bool shown, std::int64_t& integer) {
    const ScalarValue v = read_scalar(kind, in_.data() + at_);
    at_ += scalar_size(kind);
    integer = is_signed_integer(kind) ? v.integer : static_cast<std::int64_t>(v.unsigned_integer);
    if (!shown) return true;
    if (kind == ScalarKind::boolean) return put(v.unsigned_integer != 0 ? "true" : "false");
    std::array<char, kNumberText> text{};
    std::to_chars_result done{};
    if (kind == ScalarKind::float32 || kind == ScalarKind::float64) {
      if (!std::isfinite(v.real)) return put("null");
      // A float32 as the double it is exactly (0.1f is 0.10000000149011612), so a reader that parses
      // JSON numbers as doubles, as most do, gets the very value.
      done = std::to_chars(text.data(), text.data() + text.size(), v.real);
    } else if (is_signed_integer(kind)) {
      done = std::to_chars(text.data(), text.data() + text.size(), v.integer);
    } else {
      done = std::to_chars(text.data(), text.data() + text.size(), v.unsigned_integer);
    }
    return put(std::string_view(text.data(), static_cast<std::size_t>(done.ptr - text.data())));
  }

  bool enumeration(const FieldType& type, bool shown, std::int64_t& integer) {
    if (!scalar(type.scalar, false, integer)) return false;
    if (!shown) return true;
    const bool is_unsigned = !is_signed_integer(type.scalar);
    for (const EnumValue& v : type.values) {
      if (v.value == integer && !(is_unsigned && integer < 0)) return put("\"") && put(v.name) && put("\"");
    }
    at_ -= scalar_size(type.scalar);  // an unnamed value: its number
    return scalar(type.scalar, true, integer);
  }

  std::size_t count() {
    const ScalarValue v = read_scalar(ScalarKind::uint32, in_.data() + at_);
    at_ += 4;
    return static_cast<std::size_t>(v.unsigned_integer);
  }

  bool string(bool shown) {
    const std::size_t size = count();
    const std::string_view text(reinterpret_cast<const char*>(in_.data() + at_), size);
    at_ += size;
    if (!shown) return true;
    if (!put("\"")) return false;
    for (std::size_t i = 0; i < text.size();) {
      const std::size_t length = utf8_sequence(text.substr(i));
      if (!escaped(text.substr(i, std::max<std::size_t>(length, 1)), length == 0)) return false;
      i += std::max<std::size_t>(length, 1);
    }
    return put("\"");
  }

  // One UTF-8 sequence (or an invalid byte) of a string.
  bool escaped(std::string_view sequence, bool invalid) {
    if (invalid) return put("\\ufffd");
    const char c = sequence[0];
    if (sequence.size() > 1) return put(sequence);
    if (c == '"') return put("\\\"");
    if (c == '\\') return put("\\\\");
    if (static_cast<unsigned char>(c) < 0x20) {
      static constexpr char kHex[] = "0123456789abcdef";
      const char code[] = {'\\', 'u', '0', '0', kHex[(c >> 4) & 0xF], kHex[c & 0xF]};
      return put(std::string_view(code, sizeof code));
    }
    return put(sequence);
  }

  bool elements(const FieldType& element, std::size_t count, bool shown) {
    if (shown && !put("[")) return false;
    std::int64_t ignored = 0;
    for (std::size_t i = 0; i < count; ++i) {
      if (shown && i > 0 && !put(",")) return false;
      if (!value(element, shown, ignored)) return false;
    }
    return !shown || put("]");
  }

  bool put(std::string_view text) {
    if (out_.size() - out_at_ < text.size()) return false;
    std::copy(text.begin(), text.end(), out_.begin() + static_cast<std::ptrdiff_t>(out_at_));
    out_at_ += text.size();
    return true;
  }

  std::span<const std::uint8_t> in_;
  std::span<char> out_;
  const std::unordered_map<const TypeField*, std::size_t>& selectors_;
  std::size_t at_ = 0;
  std::size_t out_at_ = 0;
};

}  // namespace

JsonRepresentation::JsonRepresentation(ChannelType type) : type_(std::move(type)) {
  max_size_ = json_text::max_record_size(type_.fields);
  json_text::index_selectors(type_.fields, selectors_);
}

std::optional<std::size_t> JsonRepresentation::write(std::span<const std::uint8_t> compact, std::span<char> out) const {
  if (!check_compact(type_, compact)) return std::nullopt;
  JsonWriter writer(compact, out, selectors_);
  if (!writer.record(type_.fields)) return std::nullopt;
  return writer.written();
}

}  // namespace cosmic

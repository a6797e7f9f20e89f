// A typed event read from JSON (cosmic/json_event_reader.hpp). One recursive descent along the
// type, writing the compact layout as it goes. A record's fields must land in declaration order, so
// a field given before its turn is only checked and skipped, its position noted, and read when its
// turn comes; write()'s own order is read in one pass. Why a text is refused is kept as static
// words and a path of views into the type (no allocation) and only read() makes a text of it.
#include "cosmic/json_event_reader.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "cosmic/compact_layout.hpp"
#include "json_scanner.hpp"
#include "json_text.hpp"

namespace cosmic {
// A namespace of its own: unity builds put this file together with others of lib/core.
namespace json_reading {
namespace {

constexpr std::size_t kMaxTextBytes = std::size_t{64} << 20;  // text positions fit 32 bits
// The integers a kind holds.
std::int64_t signed_lowest(ScalarKind kind) {
  return scalar_size(kind) == 8 ? std::numeric_limits<std::int64_t>::min()
                                : -(std::int64_t{1} << (8 * scalar_size(kind) - 1));
}
std::int64_t signed_highest(ScalarKind kind) { return -(signed_lowest(kind) + 1); }
std::uint64_t unsigned_highest(ScalarKind kind) {
  if (kind == ScalarKind::boolean) return 1;
  return scalar_size(kind) == 8 ? std::numeric_limits<std::uint64_t>::max()
                                : (std::uint64_t{1} << (8 * scalar_size(kind))) - 1;
}

class JsonEventParser : public JsonScanner {
 public:
  JsonEventParser(std::string_view text, std::span<std::uint8_t> out, const json_text::Selectors& selectors)
      : JsonScanner(text), out_(out), selectors_(selectors) {}

  bool event(const std::vector<TypeField>& fields) {
    skip_space();
    if (!record(fields)) return false;
    skip_space();
    if (pos_ != text_.size()) return fail(pos_, "more text after the event");
    return true;
  }

  std::size_t written() const { return out_at_; }
  const Refusal& refusal() const { return refusal_; }

 private:
  // --- the compact layout -------------------------------------------------------------------------

  std::uint8_t* reserve(std::size_t size) {
    if (out_.size() - out_at_ < size) {
      fail(pos_, "the event does not fit the compact buffer");
      return nullptr;
    }
    std::uint8_t* at = out_.data() + out_at_;
    out_at_ += size;
    return at;
  }
  bool put(ScalarKind kind, const ScalarValue& v) {
    std::uint8_t* at = reserve(scalar_size(kind));
    if (at == nullptr) return false;
    write_scalar(kind, v, at);
    return true;
  }
  // A conditional field its selector does not select: zero bits, a count of 0 for a string or a
  // sequence (as the compact layout keeps it).
  bool zero(const FieldType& type) {
    if (const std::optional<std::size_t> size = fixed_compact_size(type)) {
      std::uint8_t* at = reserve(*size);
      if (at != nullptr && *size > 0) std::memset(at, 0, *size);
      return at != nullptr;
    }
    switch (type.kind) {
      case FieldType::Kind::array:
        for (std::uint32_t i = 0; i < type.bound; ++i) {
          if (!zero(type.element[0])) return false;
        }
        return true;
      case FieldType::Kind::record:
        for (const TypeField& f : type.fields) {
          if (!zero(f.type)) return false;
        }
        return true;
      default: {  // a string or a sequence
        std::uint8_t* at = reserve(4);
        if (at != nullptr) std::memset(at, 0, 4);
        return at != nullptr;
      }
    }
  }

  // --- values -------------------------------------------------------------------------------------

  // One value of `type`; a scalar's or an enumeration's integer goes to `integer` (for the
  // conditional fields it selects).
  bool value(const FieldType& type, std::int64_t& integer) {
    skip_space();
    switch (type.kind) {
      case FieldType::Kind::scalar:
        return scalar(type.scalar, integer);
      case FieldType::Kind::enumeration:
        return enumeration(type, integer);
      case FieldType::Kind::string:
        return string(type.bound);
      case FieldType::Kind::array:
      case FieldType::Kind::sequence:
        return elements(type.element[0], type.bound, type.kind == FieldType::Kind::array);
      case FieldType::Kind::record:
        return record(type.fields);
    }
    return false;
  }

  bool scalar(ScalarKind kind, std::int64_t& integer) {
    ScalarValue v;
    if (kind == ScalarKind::boolean) {
      const bool yes = literal("true");
      if (!yes && !literal("false")) return wrong_type("true or false");
      v.unsigned_integer = yes ? 1 : 0;
      integer = static_cast<std::int64_t>(v.unsigned_integer);
      return put(kind, v);
    }
    if (kind == ScalarKind::float32 || kind == ScalarKind::float64) {
      if (literal("null")) {
        v.real = std::numeric_limits<double>::quiet_NaN();
      } else if (!real(kind, v.real)) {
        return false;
      }
      return put(kind, v);
    }
    return whole(kind, v, integer) && put(kind, v);
  }

  bool real(ScalarKind kind, double& out) {
    NumberToken token;
    if (!number(token)) return false;
    out = nearest_double(token);
    // float32: what rounds to an infinity (2^128 - 2^103 and beyond) is beyond it.
    const double limit = kind == ScalarKind::float32 ? 0x1p128 - 0x1p103 : std::numeric_limits<double>::infinity();
    if (!(std::fabs(out) < limit)) return fail(token.begin, "a number beyond ", scalar_name(kind));
    if (kind == ScalarKind::float32) out = static_cast<float>(out);
    return true;
  }

  // An integer kind's value from a JSON integer, or from a number of integral value.
  bool whole(ScalarKind kind, ScalarValue& v, std::int64_t& integer) {
    NumberToken token;
    if (!number(token)) return false;
    const char* first = text_.data() + token.begin;
    const char* last = text_.data() + token.end;
    const bool is_signed = is_signed_integer(kind);
    const auto beyond = [&] { return fail(token.begin, "a number beyond ", scalar_name(kind)); };
    if (token.whole_syntax) {
      if (is_signed) {
        if (std::from_chars(first, last, v.integer).ec != std::errc()) return beyond();
      } else if (*first == '-') {  // -0 is 0
        if (std::any_of(first + 1, last, [](char c) { return c != '0'; })) return beyond();
      } else if (std::from_chars(first, last, v.unsigned_integer).ec != std::errc()) {
        return beyond();
      }
    } else {
      const double d = nearest_double(token);
      if (!std::isfinite(d)) return beyond();
      if (std::trunc(d) != d) return fail(token.begin, "a number that is not a whole number, for ", scalar_name(kind));
      if (is_signed) {
        if (d < -0x1p63 || d >= 0x1p63) return beyond();
        v.integer = static_cast<std::int64_t>(d);
      } else {
        if (d < 0 || d >= 0x1p64) return beyond();
        v.unsigned_integer = static_cast<std::uint64_t>(d);
      }
    }
    if (is_signed ? v.integer < signed_lowest(kind) || v.integer > signed_highest(kind)
                  : v.unsigned_integer > unsigned_highest(kind))
      return beyond();
    integer = is_signed ? v.integer : static_cast<std::int64_t>(v.unsigned_integer);
    return true;
  }

  bool enumeration(const FieldType& type, std::int64_t& integer) {
    if (peek() != '"') {
      ScalarValue v;
      if (peek() != '-' && !is_digit(peek())) return wrong_type("the name or the number of a value");
      return whole(type.scalar, v, integer) && put(type.scalar, v);
    }
    const std::size_t begin = pos_;
    std::array<std::uint8_t, kMaxNameBytes> name;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::string_view spelled;
    const Decoded decoded = decode_name(name, spelled);
    if (decoded == Decoded::invalid) return false;
    const auto named =
        std::find_if(type.values.begin(), type.values.end(), [&](const EnumValue& v) { return v.name == spelled; });
    if (decoded == Decoded::too_long || named == type.values.end()) {
      return fail(begin, "no value of the enumeration is named ", raw_string(begin));
    }
    ScalarValue v;
    v.integer = named->value;
    v.unsigned_integer = static_cast<std::uint64_t>(named->value);
    integer = named->value;
    return put(type.scalar, v);
  }

  bool string(std::uint32_t bound) {
    if (peek() != '"') return wrong_type("a string");
    const std::size_t begin = pos_;
    std::uint8_t* count = reserve(4);
    if (count == nullptr) return false;
    const std::size_t room = std::min<std::size_t>(bound, out_.size() - out_at_);
    std::size_t size = 0;
    const Decoded decoded = decode_string(out_.data() + out_at_, room, size);
    if (decoded == Decoded::invalid) return false;
    if (decoded == Decoded::too_long) {
      if (room < bound) return fail(begin, "the event does not fit the compact buffer");
      return fail(begin, "a string longer than its bound of ", {}, bound, " bytes");
    }
    out_at_ += size;
    ScalarValue v;
    v.unsigned_integer = size;
    write_scalar(ScalarKind::uint32, v, count);
    return true;
  }

  // An array (exactly `bound` elements) or a sequence (at most `bound`, its count first).
  bool elements(const FieldType& element, std::uint32_t bound, bool exact) {
    if (peek() != '[') return wrong_type("an array");
    const std::size_t begin = pos_;
    if (!enter()) return false;
    std::uint8_t* count_at = exact ? nullptr : reserve(4);
    if (!exact && count_at == nullptr) return false;
    std::uint32_t count = 0;
    skip_space();
    if (peek() == ']') {
      ++pos_;
    } else {
      for (;;) {
        skip_space();
        if (count == bound) {
          return fail(pos_,
                      exact ? "more elements than the array's length " : "more elements than the sequence's bound ", {},
                      bound);
        }
        std::int64_t ignored = 0;
        if (!value(element, ignored)) return inside({}, count);
        ++count;
        skip_space();
        if (peek() == ']' && pos_ < text_.size()) {
          ++pos_;
          break;
        }
        if (!punctuation(',', "expected , or ] after an element")) return false;
      }
    }
    --depth_;
    if (exact && count != bound) return fail(begin, "an array of another length than its ", {}, bound, " elements");
    if (!exact) {
      ScalarValue v;
      v.unsigned_integer = count;
      write_scalar(ScalarKind::uint32, v, count_at);
    }
    return true;
  }

  bool selected(const TypeField& f, const std::array<std::int64_t, kMaxRecordFields>& values) const {
    const auto selector = selectors_.find(&f);
    return selector != selectors_.end() && values[selector->second] == f.present_when->value;
  }

  bool record(const std::vector<TypeField>& fields) {
    if (peek() != '{') return wrong_type("an object");
    if (!enter()) return false;
    const std::size_t n = std::min(fields.size(), kMaxRecordFields);
    // Where each field's value starts in the text when it came before its turn (0: not yet, as no
    // value starts at byte 0), and each field's integer for the conditional fields after it. Only
    // the record's own entries are set: a sequence of records would otherwise fill 3 KiB each.
    std::array<std::uint32_t, kMaxRecordFields> given_at;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::array<std::int64_t, kMaxRecordFields> values;     // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::fill_n(given_at.begin(), n, 0);
    std::size_t next = 0;  // the next field to write
    // Writes every field from `next` on that can be written: an unselected conditional field as
    // zero bits, one given before its turn from where it was given.
    const auto catch_up = [&] {
      while (next < n) {
        const TypeField& f = fields[next];
        if (f.present_when && !selected(f, values)) {
          if (given_at[next] != 0) {
            return fail(given_at[next], "given while ", f.present_when->selector, std::nullopt,
                        " does not select it") ||
                   inside(f.name);
          }
          if (!zero(f.type)) return inside(f.name);
          values[next] = 0;
        } else if (given_at[next] != 0) {
          const std::size_t resume = pos_;
          pos_ = given_at[next];
          if (!value(f.type, values[next])) return inside(f.name);
          pos_ = resume;
        } else {
          return true;
        }
        ++next;
      }
      return true;
    };
    if (!catch_up()) return false;
    skip_space();
    if (peek() == '}') {
      ++pos_;
    } else {
      for (;;) {
        skip_space();
        const std::size_t key_at = pos_;
        std::size_t index = 0;
        if (!field_name(fields, next, index) || !punctuation(':', "expected : after a field's name")) return false;
        skip_space();
        const TypeField& f = fields[index];
        if (index < next || given_at[index] != 0) {
          const bool unselected = index < next && f.present_when && !selected(f, values);
          return (unselected
                      ? fail(key_at, "given while ", f.present_when->selector, std::nullopt, " does not select it")
                      : fail(key_at, "the field is given twice")) ||
                 inside(f.name);
        }
        if (index == next) {  // its turn (catch_up has written every unselected field before it)
          if (!value(f.type, values[index])) return inside(f.name);
          ++next;
          if (!catch_up()) return false;
        } else {
          given_at[index] = static_cast<std::uint32_t>(pos_);
          if (!skip_value()) return inside(f.name);
        }
        skip_space();
        if (peek() == '}' && pos_ < text_.size()) {
          ++pos_;
          break;
        }
        if (!punctuation(',', "expected , or } after a field")) return false;
      }
    }
    if (!catch_up()) return false;
    if (next < n) return fail(pos_ - 1, "missing") || inside(fields[next].name);
    --depth_;
    return true;
  }

  // A field's name (the key of a member) -> its index in `fields`, looked for from `hint` on.
  bool field_name(const std::vector<TypeField>& fields, std::size_t hint, std::size_t& index) {
    if (peek() != '"') return fail(pos_, "expected a field's name");
    const std::size_t begin = pos_;
    std::array<std::uint8_t, kMaxNameBytes> name;  // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::string_view spelled;
    const Decoded decoded = decode_name(name, spelled);
    if (decoded == Decoded::invalid) return false;
    const std::size_t n = fields.size();
    for (std::size_t k = 0; decoded == Decoded::ok && k < n; ++k) {
      index = (hint + k) % n;
      if (fields[index].name == spelled) return true;
    }
    return fail(begin, "no field is named ", raw_string(begin));
  }

  std::span<std::uint8_t> out_;
  const json_text::Selectors& selectors_;
  std::size_t out_at_ = 0;
};

// Runs the parser unless the text is too long; the parser (or nullopt for the length) says why not.
template <typename Refused>
std::optional<std::size_t> parse_event(const ChannelType& type, const json_text::Selectors& selectors,
                                       std::size_t max_text, std::string_view json, std::span<std::uint8_t> compact,
                                       Refused&& refused) {
  if (json.size() > max_text) {
    refused(nullptr);
    return std::nullopt;
  }
  JsonEventParser parser(json, compact, selectors);
  if (!parser.event(type.fields)) {
    refused(&parser.refusal());
    return std::nullopt;
  }
  return parser.written();
}

}  // namespace
}  // namespace json_reading

JsonEventReader::JsonEventReader(ChannelType type) : type_(std::move(type)) {
  max_compact_size_ = cosmic::max_compact_size(type_);
  max_text_size_ = std::min(2 * json_text::max_record_size(type_.fields) + 4096, json_reading::kMaxTextBytes);
  json_text::index_selectors(type_.fields, selectors_);
}

Result<std::size_t> JsonEventReader::read(std::string_view json, std::span<std::uint8_t> compact) const {
  std::string why;
  const std::optional<std::size_t> size = json_reading::parse_event(
      type_, selectors_, max_text_size_, json, compact, [&](const json_reading::Refusal* refusal) {
        why = refusal != nullptr ? refusal->text()
                                 : "a text of " + std::to_string(json.size()) + " bytes, more than the " +
                                       std::to_string(max_text_size_) + " read for an event of the type";
      });
  if (!size) return Error{why, 0, kNoChannel};
  return *size;
}

std::optional<std::size_t> JsonEventReader::read_unexplained(std::string_view json,
                                                             std::span<std::uint8_t> compact) const noexcept {
  return json_reading::parse_event(type_, selectors_, max_text_size_, json, compact,
                                   [](const json_reading::Refusal*) {});
}

}  // namespace cosmic

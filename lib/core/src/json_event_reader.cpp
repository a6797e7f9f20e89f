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
#include "json_text.hpp"

namespace cosmic {
// A namespace of its own: unity builds put this file together with others of lib/core.
namespace json_reading {
namespace {

constexpr std::size_t kMaxTextBytes = std::size_t{64} << 20;  // text positions fit 32 bits
constexpr std::size_t kMaxPathParts = 2 * kMaxJsonNesting;
constexpr std::size_t kMaxNameBytes = 64;  // valid_field_name: field and enumeration value names

// Why a text was refused: "<what><detail><number><tail>" at byte `at`, inside the value `path`
// names (innermost first: a field's name, or an element's index when the name is empty).
struct Refusal {
  struct Part {
    std::string_view name;
    std::size_t index = 0;
  };
  std::size_t at = 0;
  const char* what = "";
  std::string_view detail;
  std::optional<std::uint64_t> number;
  const char* tail = "";
  std::array<Part, kMaxPathParts> path{};
  std::size_t path_size = 0;

  std::string text() const {
    std::string where;
    for (std::size_t i = path_size; i-- > 0;) {
      if (path[i].name.empty()) {
        where += "[" + std::to_string(path[i].index) + "]";
      } else {
        where += (where.empty() ? "" : ".") + std::string(path[i].name);
      }
    }
    std::string out = where.empty() ? "byte " + std::to_string(at) : where + " (byte " + std::to_string(at) + ")";
    out += std::string(": ") + what + std::string(detail);
    if (number) out += std::to_string(*number);
    return out + tail;
  }
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// What a value starting with `c` is, for "expected a number, found a string".
const char* found_kind(char c) {
  switch (c) {
    case '{':
      return ", found an object";
    case '[':
      return ", found an array";
    case '"':
      return ", found a string";
    case 't':
    case 'f':
      return ", found true or false";
    case 'n':
      return ", found null";
    default:
      return c == '-' || is_digit(c) ? ", found a number" : ", found no JSON value";
  }
}

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

// A JSON number's span in the text, checked against JSON's grammar.
struct NumberToken {
  std::size_t begin = 0;
  std::size_t end = 0;
  bool whole_syntax = true;  // no fraction and no exponent: read as an integer
};

// The power of ten of a number's first significant digit (1234.5 -> 3, 0.01 -> -2, 5e-400 -> -400),
// to tell an overflow from an underflow when from_chars says only "out of range".
std::int64_t decimal_magnitude(std::string_view number) {
  std::size_t i = !number.empty() && number[0] == '-' ? 1 : 0;
  const std::size_t integer_begin = i;
  while (i < number.size() && is_digit(number[i])) ++i;
  std::optional<std::int64_t> first;
  for (std::size_t k = integer_begin; k < i && !first; ++k) {
    if (number[k] != '0') first = static_cast<std::int64_t>(i - k) - 1;
  }
  if (i < number.size() && number[i] == '.') {
    for (std::int64_t place = -1; ++i < number.size() && is_digit(number[i]); --place) {
      if (!first && number[i] != '0') first = place;
    }
  }
  std::int64_t exponent = 0;
  if (i < number.size() && (number[i] == 'e' || number[i] == 'E')) {
    const bool negative = ++i < number.size() && number[i] == '-';
    if (i < number.size() && (number[i] == '-' || number[i] == '+')) ++i;
    for (; i < number.size() && is_digit(number[i]); ++i) {
      exponent = std::min<std::int64_t>(exponent * 10 + (number[i] - '0'), std::int64_t{1} << 40);
    }
    if (negative) exponent = -exponent;
  }
  return first.value_or(0) + exponent;
}

class JsonEventParser {
 public:
  JsonEventParser(std::string_view text, std::span<std::uint8_t> out, const json_text::Selectors& selectors)
      : text_(text), out_(out), selectors_(selectors) {}

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
  // --- refusals -----------------------------------------------------------------------------------

  bool fail(std::size_t at, const char* what, std::string_view detail = {},
            std::optional<std::uint64_t> number = std::nullopt, const char* tail = "") {
    refusal_.at = at;
    refusal_.what = what;
    refusal_.detail = detail;
    refusal_.number = number;
    refusal_.tail = tail;
    refusal_.path_size = 0;
    return false;
  }
  bool wrong_type(const char* expected) { return fail(pos_, "expected ", expected, std::nullopt, found_kind(peek())); }
  // A refusal inside a field or an element, named on the way out.
  bool inside(std::string_view name, std::size_t index = 0) {
    if (refusal_.path_size < refusal_.path.size()) refusal_.path[refusal_.path_size++] = Refusal::Part{name, index};
    return false;
  }

  // --- text ---------------------------------------------------------------------------------------

  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
  }
  bool literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }
  bool punctuation(char c, const char* what) {
    skip_space();
    if (peek() != c || pos_ >= text_.size()) return fail(pos_, what);
    ++pos_;
    return true;
  }
  bool enter() {
    if (++depth_ > kMaxJsonNesting) return fail(pos_, "nested deeper than ", {}, kMaxJsonNesting, " arrays and objects");
    ++pos_;
    return true;
  }

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

  bool number(NumberToken& token) {
    token.begin = pos_;
    std::size_t i = pos_ + (peek() == '-' ? 1 : 0);
    const auto digit_at = [&](std::size_t at) { return at < text_.size() && is_digit(text_[at]); };
    const auto digits = [&] {
      while (digit_at(i)) ++i;
    };
    if (!digit_at(i)) return i == pos_ ? wrong_type("a number") : fail(pos_, "a number without digits");
    if (text_[i] == '0' && digit_at(i + 1)) return fail(pos_, "a number with a leading zero");
    digits();
    if (i < text_.size() && text_[i] == '.') {
      token.whole_syntax = false;
      if (!digit_at(++i)) return fail(pos_, "a number without digits after its point");
      digits();
    }
    if (i < text_.size() && (text_[i] == 'e' || text_[i] == 'E')) {
      token.whole_syntax = false;
      if (++i < text_.size() && (text_[i] == '+' || text_[i] == '-')) ++i;
      if (!digit_at(i)) return fail(pos_, "a number without digits in its exponent");
      digits();
    }
    token.end = pos_ = i;
    return true;
  }

  // The double nearest a checked number: an infinity beyond float64, a zero below its smallest.
  double nearest_double(const NumberToken& token) const {
    const std::string_view spelled = text_.substr(token.begin, token.end - token.begin);
    double d = 0;
    if (std::from_chars(spelled.data(), spelled.data() + spelled.size(), d).ec == std::errc()) return d;
    const bool negative = spelled[0] == '-';
    if (decimal_magnitude(spelled) < 0) return negative ? -0.0 : 0.0;
    return negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
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
    std::array<std::uint8_t, kMaxNameBytes> name{};
    std::size_t size = 0;
    const Decoded decoded = decode_string(name.data(), name.size(), size);
    if (decoded == Decoded::invalid) return false;
    const std::string_view spelled(reinterpret_cast<const char*>(name.data()), size);
    const auto named = std::find_if(type.values.begin(), type.values.end(),
                                    [&](const EnumValue& v) { return v.name == spelled; });
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
          return fail(pos_, exact ? "more elements than the array's length " : "more elements than the sequence's bound ",
                      {}, bound);
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
                        " does not select it") || inside(f.name);
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
          return (unselected ? fail(key_at, "given while ", f.present_when->selector, std::nullopt, " does not select it")
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
    std::array<std::uint8_t, kMaxNameBytes> name{};
    std::size_t size = 0;
    const Decoded decoded = decode_string(name.data(), name.size(), size);
    if (decoded == Decoded::invalid) return false;
    const std::string_view spelled(reinterpret_cast<const char*>(name.data()), size);
    const std::size_t n = fields.size();
    for (std::size_t k = 0; decoded == Decoded::ok && k < n; ++k) {
      index = (hint + k) % n;
      if (fields[index].name == spelled) return true;
    }
    return fail(begin, "no field is named ", raw_string(begin));
  }

  // The characters of the string starting at `begin` as the text spells them (for a refusal).
  std::string_view raw_string(std::size_t begin) const {
    const std::string_view rest = text_.substr(begin + 1, kMaxNameBytes + 2);
    return rest.substr(0, rest.find('"'));
  }

  // --- strings ------------------------------------------------------------------------------------

  enum class Decoded : std::uint8_t { ok, too_long, invalid };

  // The string at pos_ (its opening quote) into `out` (at most `room` bytes; null: only checked):
  // escapes decoded to UTF-8, every raw byte valid UTF-8. ok: pos_ after its closing quote, `size`
  // the bytes; too_long: it needs more than `room`; invalid: the refusal says why.
  Decoded decode_string(std::uint8_t* out, std::size_t room, std::size_t& size) {
    const auto emit = [&](const char* bytes, std::size_t count) {
      if (room - size < count) return false;
      if (out != nullptr) std::memcpy(out + size, bytes, count);
      size += count;
      return true;
    };
    std::size_t i = pos_ + 1;
    while (i < text_.size()) {
      const char c = text_[i];
      if (c == '"') {
        pos_ = i + 1;
        return Decoded::ok;
      }
      if (static_cast<unsigned char>(c) < 0x20) {
        fail(i, "a control character in a string (JSON escapes them)");
        return Decoded::invalid;
      }
      std::size_t length = 1;
      std::array<char, 4> utf8{};
      const char* bytes = text_.data() + i;
      std::size_t count = 1;
      if (c == '\\') {
        if (!escape(i, length, utf8, count)) return Decoded::invalid;
        bytes = utf8.data();
      } else if (static_cast<unsigned char>(c) >= 0x80) {
        length = count = json_text::utf8_sequence(text_.substr(i));
        if (length == 0) {
          fail(i, "a byte that is not part of valid UTF-8");
          return Decoded::invalid;
        }
      }
      if (!emit(bytes, count)) return Decoded::too_long;
      i += length;
    }
    fail(pos_, "a string without its closing quote");
    return Decoded::invalid;
  }

  // The escape at `at` (a backslash): its `length` in the text and its `count` bytes of UTF-8.
  bool escape(std::size_t at, std::size_t& length, std::array<char, 4>& utf8, std::size_t& count) {
    const char kind = at + 1 < text_.size() ? text_[at + 1] : '\0';
    length = 2;
    count = 1;
    static constexpr std::string_view kSimple = "\"\\/bfnrt";
    static constexpr std::string_view kMeaning = "\"\\/\b\f\n\r\t";
    if (const std::size_t simple = kSimple.find(kind); kind != '\0' && simple != std::string_view::npos) {
      utf8[0] = kMeaning[simple];
      return true;
    }
    std::uint32_t code = 0;
    if (kind != 'u' || !hex4(at + 2, code)) return fail(at, "an invalid escape in a string");
    length = 6;
    if (code >= 0xDC00 && code <= 0xDFFF) return fail(at, "an unpaired surrogate escape in a string");
    if (code >= 0xD800 && code <= 0xDBFF) {
      std::uint32_t low = 0;
      if (text_.substr(at + 6, 2) != "\\u" || !hex4(at + 8, low) || low < 0xDC00 || low > 0xDFFF)
        return fail(at, "an unpaired surrogate escape in a string");
      code = 0x10000 + ((code - 0xD800) << 10) + (low - 0xDC00);
      length = 12;
    }
    const auto byte = [](std::uint32_t v) { return static_cast<char>(static_cast<unsigned char>(v)); };
    if (code < 0x80) {
      utf8[0] = byte(code);
    } else if (code < 0x800) {
      utf8 = {byte(0xC0 | (code >> 6)), byte(0x80 | (code & 0x3F))};
      count = 2;
    } else if (code < 0x10000) {
      utf8 = {byte(0xE0 | (code >> 12)), byte(0x80 | ((code >> 6) & 0x3F)), byte(0x80 | (code & 0x3F))};
      count = 3;
    } else {
      utf8 = {byte(0xF0 | (code >> 18)), byte(0x80 | ((code >> 12) & 0x3F)), byte(0x80 | ((code >> 6) & 0x3F)),
              byte(0x80 | (code & 0x3F))};
      count = 4;
    }
    return true;
  }

  bool hex4(std::size_t at, std::uint32_t& code) const {
    if (text_.size() < at + 4) return false;
    const char* first = text_.data() + at;
    if (!std::all_of(first, first + 4, [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }))
      return false;
    return std::from_chars(first, first + 4, code, 16).ec == std::errc();
  }

  // --- skipping a value given before its turn -----------------------------------------------------

  bool skip_value() {
    skip_space();
    const char c = peek();
    if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      if (!enter()) return false;
      skip_space();
      if (peek() == close && pos_ < text_.size()) {
        ++pos_;
        --depth_;
        return true;
      }
      for (;;) {
        skip_space();
        if (c == '{') {
          std::size_t ignored = 0;
          if (peek() != '"') return fail(pos_, "expected a member's name");
          if (decode_string(nullptr, std::numeric_limits<std::size_t>::max(), ignored) != Decoded::ok) return false;
          if (!punctuation(':', "expected : after a member's name")) return false;
        }
        if (!skip_value()) return false;
        skip_space();
        if (peek() == close && pos_ < text_.size()) {
          ++pos_;
          --depth_;
          return true;
        }
        if (!punctuation(',', c == '{' ? "expected , or } after a member" : "expected , or ] after an element"))
          return false;
      }
    }
    if (c == '"') {
      std::size_t ignored = 0;
      return decode_string(nullptr, std::numeric_limits<std::size_t>::max(), ignored) == Decoded::ok;
    }
    if (literal("true") || literal("false") || literal("null")) return true;
    NumberToken token;
    return number(token);
  }

  std::string_view text_;
  std::span<std::uint8_t> out_;
  const json_text::Selectors& selectors_;
  std::size_t pos_ = 0;
  std::size_t out_at_ = 0;
  std::size_t depth_ = 0;
  Refusal refusal_;
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
  const std::optional<std::size_t> size =
      json_reading::parse_event(type_, selectors_, max_text_size_, json, compact, [&](const json_reading::Refusal* refusal) {
        why = refusal != nullptr ? refusal->text()
                                 : "a text of " + std::to_string(json.size()) + " bytes, more than the " +
                                       std::to_string(max_text_size_) + " read for an event of the type";
      });
  if (!size) return Error{why, 0, kNoChannel};
  return *size;
}

std::optional<std::size_t> JsonEventReader::read_unexplained(std::string_view json,
                                                             std::span<std::uint8_t> compact) const noexcept {
  return json_reading::parse_event(type_, selectors_, max_text_size_, json, compact, [](const json_reading::Refusal*) {});
}

}  // namespace cosmic

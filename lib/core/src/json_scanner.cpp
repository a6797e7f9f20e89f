// The lexical layer of the JSON event reader (json_scanner.hpp).
#include "json_scanner.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>

#include "json_text.hpp"

namespace cosmic::json_reading {
namespace {

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

}  // namespace

std::string Refusal::text() const {
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

bool JsonScanner::wrong_type(const char* expected) {
  return fail(pos_, "expected ", expected, std::nullopt, found_kind(peek()));
}

bool JsonScanner::number(NumberToken& token) {
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
double JsonScanner::nearest_double(const NumberToken& token) const {
  const std::string_view spelled = text_.substr(token.begin, token.end - token.begin);
  double d = 0;
  if (std::from_chars(spelled.data(), spelled.data() + spelled.size(), d).ec == std::errc()) return d;
  const bool negative = spelled[0] == '-';
  if (decimal_magnitude(spelled) < 0) return negative ? -0.0 : 0.0;
  return negative ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
}

// The characters of the string starting at `begin` as the text spells them (for a refusal).
std::string_view JsonScanner::raw_string(std::size_t begin) const {
  const std::string_view rest = text_.substr(begin + 1, kMaxNameBytes + 2);
  return rest.substr(0, rest.find('"'));
}

// The string at pos_ (its opening quote) into `out` (at most `room` bytes; null: only checked):
// escapes decoded to UTF-8, every raw byte valid UTF-8. ok: pos_ after its closing quote, `size`
// the bytes; too_long: it needs more than `room`; invalid: the refusal says why.
JsonScanner::Decoded JsonScanner::decode_string(std::uint8_t* out, std::size_t room, std::size_t& size) {
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
bool JsonScanner::escape(std::size_t at, std::size_t& length, std::array<char, 4>& utf8, std::size_t& count) {
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

bool JsonScanner::hex4(std::size_t at, std::uint32_t& code) const {
  if (text_.size() < at + 4) return false;
  const char* first = text_.data() + at;
  if (!std::all_of(first, first + 4, [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }))
    return false;
  return std::from_chars(first, first + 4, code, 16).ec == std::errc();
}

bool JsonScanner::skip_value() {
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

}  // namespace cosmic::json_reading

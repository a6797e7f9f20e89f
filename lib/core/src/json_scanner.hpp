// The lexical layer of the JSON event reader (cosmic/json_event_reader.hpp): a position in a
// text, its whitespace, literals, numbers (JSON's grammar checked, the double nearest them),
// strings (escapes decoded to UTF-8, every raw byte valid UTF-8), skipping a whole value up to
// kMaxJsonNesting deep, and the refusal that says where and why a text is not read, kept as static
// words and views (nothing allocated until Refusal::text()). Internal to lib/core; one scanner per
// read, on the reading thread.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/json_event_reader.hpp"

namespace cosmic::json_reading {

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

  // "pose.ranges[3] (byte 57): a number beyond float32"
  std::string text() const;
};

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
inline bool is_digit(char c) { return c >= '0' && c <= '9'; }

// A JSON number's span in the text, checked against JSON's grammar.
struct NumberToken {
  std::size_t begin = 0;
  std::size_t end = 0;
  bool whole_syntax = true;  // no fraction and no exponent: read as an integer
};

class JsonScanner {
 public:
  explicit JsonScanner(std::string_view text) : text_(text) {}
  const Refusal& refusal() const { return refusal_; }

 protected:
  enum class Decoded : std::uint8_t { ok, too_long, invalid };

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
  bool wrong_type(const char* expected);
  // A refusal inside a field or an element, named on the way out.
  bool inside(std::string_view name, std::size_t index = 0) {
    if (refusal_.path_size < refusal_.path.size()) refusal_.path[refusal_.path_size++] = Refusal::Part{name, index};
    return false;
  }

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
    if (++depth_ > kMaxJsonNesting)
      return fail(pos_, "nested deeper than ", {}, kMaxJsonNesting, " arrays and objects");
    ++pos_;
    return true;
  }

  bool number(NumberToken& token);
  // The double nearest a checked number: an infinity beyond float64, a zero below its smallest.
  double nearest_double(const NumberToken& token) const;
  // The characters of the string starting at `begin` as the text spells them (for a refusal).
  std::string_view raw_string(std::size_t begin) const;
  // The string at pos_ (its opening quote) into `out` (at most `room` bytes; null: only checked):
  // escapes decoded to UTF-8, every raw byte valid UTF-8. ok: pos_ after its closing quote, `size`
  // the bytes; too_long: it needs more than `room`; invalid: the refusal says why.
  Decoded decode_string(std::uint8_t* out, std::size_t room, std::size_t& size);
  // A field's or an enumeration value's name (at most kMaxNameBytes; too_long: no such name) into
  // `buffer`, `spelled` its bytes there.
  Decoded decode_name(std::array<std::uint8_t, kMaxNameBytes>& buffer, std::string_view& spelled) {
    std::size_t size = 0;
    const Decoded decoded = decode_string(buffer.data(), buffer.size(), size);
    spelled = std::string_view(reinterpret_cast<const char*>(buffer.data()), size);
    return decoded;
  }
  // A whole value of any kind, checked and passed over.
  bool skip_value();

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t depth_ = 0;  // arrays and objects entered
  Refusal refusal_;

 private:
  // The escape at `at` (a backslash): its `length` in the text and its `count` bytes of UTF-8.
  bool escape(std::size_t at, std::size_t& length, std::array<char, 4>& utf8, std::size_t& count);
  bool hex4(std::size_t at, std::uint32_t& code) const;
};

}  // namespace cosmic::json_reading

// IDL literals and annotations (idl_syntax.hpp), as OMG IDL 4.2 section 7.2.6 writes literals.
#include "idl_syntax.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include "cosmic/compact_layout.hpp"

namespace cosmic::idl_detail {
namespace {

int digit_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return 99;
}

std::optional<std::uint64_t> digits_in_base(std::string_view digits, int base) {
  if (digits.empty()) return std::nullopt;
  std::uint64_t value = 0;
  for (const char c : digits) {
    const int d = digit_value(c);
    if (d >= base) return std::nullopt;
    if (value > (std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(d)) /
                    static_cast<std::uint64_t>(base)) {
      return std::nullopt;
    }
    value = value * static_cast<std::uint64_t>(base) + static_cast<std::uint64_t>(d);
  }
  return value;
}

// The character an escape after '\' stands for, and how many characters of `rest` it took.
std::optional<std::pair<char, std::size_t>> escape(std::string_view rest) {
  if (rest.empty()) return std::nullopt;
  switch (rest[0]) {
    case 'n':
      return std::pair{'\n', std::size_t{1}};
    case 't':
      return std::pair{'\t', std::size_t{1}};
    case 'v':
      return std::pair{'\v', std::size_t{1}};
    case 'b':
      return std::pair{'\b', std::size_t{1}};
    case 'r':
      return std::pair{'\r', std::size_t{1}};
    case 'f':
      return std::pair{'\f', std::size_t{1}};
    case 'a':
      return std::pair{'\a', std::size_t{1}};
    case '\\':
    case '?':
    case '\'':
    case '"':
      return std::pair{rest[0], std::size_t{1}};
    default:
      break;
  }
  std::size_t length = 0;
  int base = 8;
  std::size_t start = 0;
  if (rest[0] == 'x') {
    base = 16;
    start = 1;
    while (start + length < rest.size() && length < 2 && digit_value(rest[start + length]) < 16) ++length;
  } else {
    while (length < rest.size() && length < 3 && digit_value(rest[length]) < 8) ++length;
  }
  const auto value = digits_in_base(rest.substr(start, length), base);
  if (!value || *value > 255) return std::nullopt;
  return std::pair{static_cast<char>(*value), start + length};
}

}  // namespace

std::optional<std::uint64_t> integer_literal(std::string_view text) {
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X'))
    return digits_in_base(text.substr(2), 16);
  if (text.size() > 1 && text[0] == '0') return digits_in_base(text.substr(1), 8);
  return digits_in_base(text, 10);
}

std::optional<double> float_literal(std::string_view text) {
  if (const auto whole = integer_literal(text)) return static_cast<double>(*whole);
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<std::string> string_literal(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\\') {
      out += text[i];
      continue;
    }
    const auto escaped = escape(text.substr(i + 1));
    if (!escaped || escaped->first == '\0') return std::nullopt;
    out += escaped->first;
    i += escaped->second;
  }
  return out;
}

std::optional<std::string> integer_value_text(ScalarKind kind, std::uint64_t magnitude, bool negative) {
  if (!is_integer(kind)) return std::nullopt;
  const auto bits = static_cast<unsigned>(scalar_size(kind) * 8);
  if (negative && magnitude != 0) {
    if (!is_signed_integer(kind) || magnitude > (std::uint64_t{1} << (bits - 1))) return std::nullopt;
    return "-" + std::to_string(magnitude);
  }
  const std::uint64_t limit = is_signed_integer(kind) ? (std::uint64_t{1} << (bits - 1)) - 1
                              : bits == 64            ? std::numeric_limits<std::uint64_t>::max()
                                                      : (std::uint64_t{1} << bits) - 1;
  if (magnitude > limit) return std::nullopt;
  return std::to_string(magnitude);
}

const AnnotationValue* Annotation::param(std::string_view key) const {
  for (const auto& [name, value] : params) {
    if (name == key) return &value;
  }
  if (key == "value" && params.size() == 1 && params[0].first.empty()) return &params[0].second;
  return nullptr;
}

bool Annotation::enabled() const {
  const AnnotationValue* value = param("value");
  return value == nullptr || value->text != "FALSE";
}

std::optional<double> annotation_number(const AnnotationValue& value) {
  if (value.kind != AnnotationValue::Kind::number) return std::nullopt;
  const bool negative = !value.text.empty() && value.text[0] == '-';
  const auto magnitude = float_literal(std::string_view(value.text).substr(negative ? 1 : 0));
  if (!magnitude) return std::nullopt;
  return negative ? -*magnitude : *magnitude;
}

}  // namespace cosmic::idl_detail

// Pieces of the IDL reader (idl_type_parser.cpp) that need no parser state: literals (integers,
// floats, strings with their escapes) and annotations with their parameters as read. Internal to
// cosmic_core's IDL reader; pure functions and plain values.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosmic/channel_type.hpp"

namespace cosmic::idl_detail {

// An IDL integer literal: decimal, 0x hexadecimal or 0 octal; nullopt when malformed or beyond 64 bits.
std::optional<std::uint64_t> integer_literal(std::string_view text);
// A floating-point literal ("1.5", ".5e-3", "2."; a whole number too); nullopt when malformed,
// fixed-point ("1.5d") or not finite.
std::optional<double> float_literal(std::string_view text);
// A string literal's characters with its escapes resolved (\n \t \v \b \r \f \a \\ \? \' \" \ooo
// \xhh); nullopt for an unknown escape or a NUL, which IDL strings cannot hold.
std::optional<std::string> string_literal(std::string_view text);

// Whether `value` (negated when `negative`) fits the integer `kind`; the value as text if so.
std::optional<std::string> integer_value_text(ScalarKind kind, std::uint64_t magnitude, bool negative);

// One annotation as written: @name, @name(value), @name(key=value, ...). A value is a number (a
// leading '-' kept), the characters of one or more adjacent string literals, or a name (TRUE,
// FINAL, a scoped name).
struct AnnotationValue {
  enum class Kind { number, string, name };
  Kind kind = Kind::name;
  std::string text;
};

struct Annotation {
  std::string name;
  int line = 0, column = 0;
  std::vector<std::pair<std::string, AnnotationValue>> params;  // key "" for a positional value

  // The value of `key`, or else a lone positional value when `key` is "value" (@unit("m") is
  // @unit(value="m")).
  const AnnotationValue* param(std::string_view key) const;
  // For @key and @optional: no value or TRUE.
  bool enabled() const;
};

// A number an annotation gives (@min(-1.5), @range(max=0x10)).
std::optional<double> annotation_number(const AnnotationValue& value);

}  // namespace cosmic::idl_detail

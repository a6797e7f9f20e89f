// Reading LCM type files (cosmic/lcm_types.hpp): a lexer for lcm-gen's language (identifiers,
// numbers, one-character punctuation, // and /* */ comments) and a parser of `package`, `struct`,
// members with their dimensions, and `const` lists. Each problem is reported at its line and
// column, and the parser goes on at the next ';' or '}', so one pass reports them all.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include "cosmic/lcm_types.hpp"
#include "cosmic/units.hpp"

namespace cosmic {
namespace {

enum class Kind { identifier, number, punct, end };

struct Token {
  Kind kind = Kind::end;
  std::string_view text;
  int line = 1, column = 1;
  bool is(std::string_view word) const { return kind != Kind::end && text == word; }
};

bool identifier_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
bool digit(char c) { return c >= '0' && c <= '9'; }

class Lexer {
 public:
  explicit Lexer(std::string_view text) : text_(text) {}

  Token next() {
    skip_blanks_and_comments();
    Token t;
    t.line = line_;
    t.column = column_;
    if (pos_ >= text_.size() || failure_) return t;
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (identifier_start(c)) {
      while (pos_ < text_.size() && (identifier_start(text_[pos_]) || digit(text_[pos_]))) step();
      t.kind = Kind::identifier;
    } else if (digit(c) || ((c == '-' || c == '+' || c == '.') && pos_ + 1 < text_.size() && digit(text_[pos_ + 1]))) {
      step();
      while (pos_ < text_.size()) {
        const char d = text_[pos_];
        const bool exponent_sign = (d == '-' || d == '+') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E');
        if (!(digit(d) || identifier_start(d) || d == '.' || exponent_sign)) break;
        step();
      }
      t.kind = Kind::number;
    } else {
      step();
      t.kind = Kind::punct;
    }
    t.text = text_.substr(start, pos_ - start);
    return t;
  }

  const std::optional<LcmError>& failure() const { return failure_; }

 private:
  void step() {
    if (text_[pos_++] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
  }

  void skip_blanks_and_comments() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') {
        step();
      } else if (text_.substr(pos_, 2) == "//") {
        while (pos_ < text_.size() && text_[pos_] != '\n') step();
      } else if (text_.substr(pos_, 2) == "/*") {
        const int line = line_, column = column_;
        const std::size_t end = text_.find("*/", pos_ + 2);
        if (end == std::string_view::npos) {
          failure_ = LcmError{line, column, "unterminated comment: no '*/' before the end of the text"};
          pos_ = text_.size();
          return;
        }
        while (pos_ < end + 2) step();
      } else {
        return;
      }
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  std::optional<LcmError> failure_;
};

bool is_integer_type(std::string_view t) { return t == "int8_t" || t == "int16_t" || t == "int32_t" || t == "int64_t"; }

// Whether a constant's value fits its type.
bool constant_fits(std::string_view type, std::string_view value) {
  if (type == "float" || type == "double") {
    double d = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), d);
    if (error != std::errc{} || end != value.data() + value.size() || !std::isfinite(d)) return false;
    return type == "double" || std::fabs(d) <= std::numeric_limits<float>::max();
  }
  std::int64_t v = 0;
  const bool hex = value.starts_with("0x") || value.starts_with("0X");
  const auto digits = hex ? value.substr(2) : value;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), v, hex ? 16 : 10);
  if (error != std::errc{} || end != digits.data() + digits.size()) return false;
  const int bits = type == "int8_t" ? 8 : type == "int16_t" ? 16 : type == "int32_t" ? 32 : 64;
  if (bits == 64) return true;
  return v >= -(std::int64_t{1} << (bits - 1)) && v < (std::int64_t{1} << (bits - 1));
}

class Parser {
 public:
  explicit Parser(std::string_view text) : lexer_(text) { advance(); }

  LcmTypeFile run() && {
    while (peek_.kind != Kind::end) top_level();
    if (lexer_.failure()) error(lexer_.failure()->line, lexer_.failure()->column, lexer_.failure()->message);
    std::stable_sort(file_.errors.begin(), file_.errors.end(), [](const auto& a, const auto& b) {
      return std::pair{a.line, a.column} < std::pair{b.line, b.column};
    });
    if (unreported_ > 0) {
      file_.errors.push_back(LcmError{0, 0, std::to_string(unreported_) + " more errors not reported"});
    }
    return std::move(file_);
  }

 private:
  Token advance() {
    const Token previous = peek_;
    peek_ = lexer_.next();
    return previous;
  }

  void error(int line, int column, std::string message) {
    if (file_.errors.size() < kMaxReportedTextErrors) {
      file_.errors.push_back(LcmError{line, column, std::move(message)});
    } else {
      ++unreported_;
    }
  }
  void error_at(const Token& t, std::string message) { error(t.line, t.column, std::move(message)); }

  void expected(std::string_view what) {
    error_at(peek_,
             "expected " + std::string(what) +
                 (peek_.kind == Kind::end ? ", found the end of the text" : ", found " + quote_value(peek_.text)));
  }

  // Past the next ';' (or to a '}' it leaves for the struct), for recovery.
  void skip_statement() {
    while (peek_.kind != Kind::end && !peek_.is("}")) {
      if (advance().is(";")) return;
    }
  }

  bool take(std::string_view punct, std::string_view what) {
    if (peek_.is(punct)) {
      advance();
      return true;
    }
    expected(what);
    return false;
  }

  std::optional<std::string> qualified_name() {
    if (peek_.kind != Kind::identifier) return std::nullopt;
    std::string name(advance().text);
    while (peek_.is(".")) {
      advance();
      if (peek_.kind != Kind::identifier) return std::nullopt;
      name += "." + std::string(advance().text);
    }
    return name;
  }

  void top_level() {
    const Token t = advance();
    if (t.is("package")) {
      const auto name = qualified_name();
      if (!name) {
        expected("the package name after 'package'");
        return skip_statement();
      }
      package_ = *name;
      take(";", "';' after the package name");  // without it, what follows is the next statement
      return;
    }
    if (t.is("struct")) return structure(t);
    if (t.is("enum")) {
      error_at(t, "LCM enums (deprecated in lcm-gen) are not read: declare the values as constants of an integer");
      while (peek_.kind != Kind::end && !advance().is("}")) {
      }
      return;
    }
    error_at(t, "expected 'package' or 'struct', found " + quote_value(t.text));
  }

  void structure(const Token& keyword) {
    LcmStruct s;
    s.package = package_;
    s.line = keyword.line;
    s.column = keyword.column;
    if (peek_.kind != Kind::identifier) return expected("the struct's name after 'struct'");
    s.name = std::string(advance().text);
    if (!take("{", "'{' after the struct's name")) return;
    while (peek_.kind != Kind::end && !peek_.is("}")) {
      if (peek_.is("const")) {
        advance();
        constants(s);
      } else {
        members(s);
      }
    }
    if (!take("}", "'}' at the end of struct " + s.name)) return;
    check_struct(s);
    if (file_.structs.size() >= kLcmMaxStructs) {
      return error_at(keyword, "more than " + std::to_string(kLcmMaxStructs) + " structs (the limit of one file)");
    }
    if (file_.find(s.full_name()) != nullptr) return error_at(keyword, "struct " + s.full_name() + " defined twice");
    file_.structs.push_back(std::move(s));
  }

  // TYPE name[dims] {, name[dims]} ;
  void members(LcmStruct& s) {
    const auto type = qualified_name();
    if (!type) {
      expected("a member's type or 'const'");
      return skip_statement();
    }
    const std::string full_type = lcm_is_primitive(*type) || type->find('.') != std::string::npos || package_.empty()
                                      ? *type
                                      : package_ + "." + *type;
    do {
      if (peek_.kind != Kind::identifier) {
        expected("the member's name after its type");
        return skip_statement();
      }
      const Token name = advance();
      LcmMember m{std::string(name.text), full_type, {}, name.line, name.column};
      while (peek_.is("[")) {
        advance();
        if (peek_.kind != Kind::number && peek_.kind != Kind::identifier) {
          expected("an array's size (a number or an integer member) after '['");
          return skip_statement();
        }
        const Token size = advance();
        m.dimensions.push_back(LcmDimension{size.kind == Kind::identifier, std::string(size.text)});
        if (!take("]", "']' after the array's size")) return skip_statement();
      }
      if (s.members.size() >= kLcmMaxMembers) {
        error_at(name, "struct " + s.name + " has more than " + std::to_string(kLcmMaxMembers) + " members");
      } else {
        s.members.push_back(std::move(m));
      }
    } while (peek_.is(",") && advance().is(","));
    if (!take(";", "';' after the member")) skip_statement();
  }

  // const TYPE NAME = VALUE {, NAME = VALUE} ;
  void constants(LcmStruct& s) {
    if (peek_.kind != Kind::identifier) {
      expected("the constant's type after 'const'");
      return skip_statement();
    }
    const Token type = advance();
    const bool numeric = is_integer_type(type.text) || type.is("float") || type.is("double");
    if (!numeric) error_at(type, "a constant is an integer, float or double, not " + quote_value(type.text));
    do {
      if (peek_.kind != Kind::identifier) {
        expected("the constant's name");
        return skip_statement();
      }
      const Token name = advance();
      if (!take("=", "'=' after the constant's name")) return skip_statement();
      if (peek_.kind != Kind::number) {
        expected("the constant's value");
        return skip_statement();
      }
      const Token value = advance();
      if (numeric && !constant_fits(type.text, value.text)) {
        error_at(value, "constant " + std::string(name.text) + " = " + quote_value(value.text) + " does not fit " +
                            std::string(type.text));
      }
      s.constants.push_back(
          LcmConstant{std::string(name.text), std::string(type.text), std::string(value.text), name.line, name.column});
    } while (peek_.is(",") && advance().is(","));
    if (!take(";", "';' after the constants")) skip_statement();
  }

  // Names unique; a variable dimension names an earlier scalar integer member; a fixed one is a
  // positive whole number.
  void check_struct(const LcmStruct& s) {
    std::set<std::string> names;
    for (std::size_t i = 0; i < s.members.size(); ++i) {
      const LcmMember& m = s.members[i];
      if (!names.insert(m.name).second) error(m.line, m.column, "member " + m.name + " declared twice in " + s.name);
      if (m.dimensions.size() > kLcmMaxDimensions) {
        error(m.line, m.column,
              "member " + m.name + " has more than " + std::to_string(kLcmMaxDimensions) + " dimensions");
      }
      for (const LcmDimension& d : m.dimensions) check_dimension(s, i, d);
    }
    for (const LcmConstant& c : s.constants) {
      if (!names.insert(c.name).second) error(c.line, c.column, "constant " + c.name + " repeats a name of " + s.name);
    }
  }

  void check_dimension(const LcmStruct& s, std::size_t index, const LcmDimension& d) {
    const LcmMember& m = s.members[index];
    if (!d.variable) {
      std::uint32_t size = 0;
      const auto [end, error_code] = std::from_chars(d.size.data(), d.size.data() + d.size.size(), size);
      if (error_code != std::errc{} || end != d.size.data() + d.size.size() || size == 0 || size > kMaxTypeBound) {
        error(m.line, m.column,
              "array size " + quote_value(d.size) + " of " + m.name + " is not 1.." + std::to_string(kMaxTypeBound));
      }
      return;
    }
    const auto count = std::find_if(s.members.begin(), s.members.begin() + static_cast<std::ptrdiff_t>(index),
                                    [&](const LcmMember& other) { return other.name == d.size; });
    if (count == s.members.begin() + static_cast<std::ptrdiff_t>(index) || !is_integer_type(count->type) ||
        !count->dimensions.empty()) {
      error(m.line, m.column,
            "the size of " + m.name + ", " + quote_value(d.size) + ", is not an integer member declared before it");
    }
  }

  Lexer lexer_;
  Token peek_;
  LcmTypeFile file_;
  std::string package_;
  std::size_t unreported_ = 0;
};

}  // namespace

bool lcm_is_primitive(std::string_view type) {
  return is_integer_type(type) || type == "byte" || type == "float" || type == "double" || type == "string" ||
         type == "boolean";
}

const LcmStruct* LcmTypeFile::find(std::string_view full_name) const {
  const auto hit =
      std::find_if(structs.begin(), structs.end(), [&](const LcmStruct& s) { return s.full_name() == full_name; });
  return hit == structs.end() ? nullptr : &*hit;
}

LcmTypeFile parse_lcm_types(std::string_view text) {
  if (text.size() > kLcmMaxTextBytes) {
    LcmTypeFile file;
    file.errors.push_back(LcmError{0, 0,
                                   "the LCM type file has " + std::to_string(text.size()) +
                                       " bytes, more than the limit of " + std::to_string(kLcmMaxTextBytes)});
    return file;
  }
  return Parser(text).run();
}

}  // namespace cosmic

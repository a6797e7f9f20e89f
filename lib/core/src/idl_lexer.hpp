// The lexer of the IDL reader (idl_type_parser.cpp): cuts an OMG IDL text into tokens, the only
// place that knows about characters, comments and preprocessor lines. It streams: one token at a
// time, with its position for located errors. Internal to cosmic_core's IDL reader; a value used
// by one thread.
//
// Not the DBC lexer (dbc_lexer.hpp): IDL has // and /* */ comments, "::" scoped names, string
// escapes, and preprocessor directives that take a whole line; DBC has none of these.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace cosmic::idl_detail {

enum class TokenKind { identifier, number, string, punct, directive, end };

struct Token {
  TokenKind kind = TokenKind::end;
  // identifier, number, punct ("::" is one token): as written; string: between the quotes, escapes
  // as written; directive: the line after '#', comment and trailing blanks included.
  std::string_view text;
  int line = 1, column = 1;
  // Keywords and punctuation; a string's or a directive's content never matches.
  bool is(std::string_view word) const {
    return (kind == TokenKind::identifier || kind == TokenKind::punct) && text == word;
  }
};

struct LexFailure {
  int line = 0, column = 0;
  std::string message;
};

inline bool idl_identifier_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
inline bool idl_digit(char c) { return c >= '0' && c <= '9'; }
inline bool idl_identifier_char(char c) { return idl_identifier_start(c) || idl_digit(c); }

class Lexer {
 public:
  explicit Lexer(std::string_view text) : text_(text) {}

  // The next token; `end` forever once the text is used up, a comment or string never closes.
  Token next() {
    const bool line_start = skip_blanks_and_comments();
    Token t;
    t.line = line_;
    t.column = column_;
    if (failure_ || pos_ >= text_.size()) return t;
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '#' && line_start) return directive(t);
    if (c == '"') return string(t);
    if (idl_identifier_start(c)) {
      while (pos_ < text_.size() && idl_identifier_char(text_[pos_])) step();
      t.kind = TokenKind::identifier;
    } else if (idl_digit(c) || (c == '.' && idl_digit(at(1)))) {
      number();
      t.kind = TokenKind::number;
    } else {
      step();
      if (c == ':' && at(0) == ':') step();
      t.kind = TokenKind::punct;
    }
    t.text = text_.substr(start, pos_ - start);
    return t;
  }

  const std::optional<LexFailure>& failure() const { return failure_; }

 private:
  char at(std::size_t offset) const { return pos_ + offset < text_.size() ? text_[pos_ + offset] : '\0'; }

  void step() {
    if (text_[pos_++] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
  }

  // True when nothing but blanks and comments stand before the next character on its line (a
  // directive's '#' must be first on its line).
  bool skip_blanks_and_comments() {
    bool line_start = line_start_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        line_start = true;
        step();
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        step();
      } else if (c == '/' && at(1) == '/') {
        while (pos_ < text_.size() && text_[pos_] != '\n') step();
      } else if (c == '/' && at(1) == '*') {
        if (!block_comment()) return false;
      } else {
        break;
      }
    }
    line_start_ = false;
    return line_start;
  }

  bool block_comment() {
    const int line = line_, column = column_;
    const std::size_t end = text_.find("*/", pos_ + 2);
    if (end == std::string_view::npos) {
      failure_ = LexFailure{line, column, "unterminated comment: no '*/' before the end of the text"};
      pos_ = text_.size();
      return false;
    }
    while (pos_ < end + 2) step();
    return true;
  }

  // Digits, letters, '_' and '.', so that "0x1F", "1.5e3" or "12abc" stay one (maybe bad) number;
  // a sign inside only right after a decimal exponent's 'e'.
  void number() {
    const bool hex = at(0) == '0' && (at(1) == 'x' || at(1) == 'X');
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      const bool exponent_sign =
          !hex && (c == '-' || c == '+') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E') && idl_digit(at(1));
      if (!idl_identifier_char(c) && c != '.' && !exponent_sign) break;
      step();
    }
  }

  // "...": one line; \" and \\ do not end it.
  Token string(Token& t) {
    step();
    const std::size_t content = pos_;
    while (pos_ < text_.size() && text_[pos_] != '"' && text_[pos_] != '\n') {
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size() && text_[pos_ + 1] != '\n') step();
      step();
    }
    if (pos_ >= text_.size() || text_[pos_] != '"') {
      failure_ = LexFailure{t.line, t.column, "unterminated string: no closing '\"' on its line"};
      pos_ = text_.size();
      return Token{TokenKind::end, {}, t.line, t.column};
    }
    t.kind = TokenKind::string;
    t.text = text_.substr(content, pos_ - content);
    step();
    return t;
  }

  // '#' to the end of its line (no continuation lines: the directives read fit one).
  Token directive(Token& t) {
    step();
    const std::size_t content = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n') step();
    std::string_view line = text_.substr(content, pos_ - content);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t' || line.back() == '\r')) line.remove_suffix(1);
    t.kind = TokenKind::directive;
    t.text = line;
    line_start_ = true;  // the next token starts a line of its own
    return t;
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  bool line_start_ = true;
  std::optional<LexFailure> failure_;
};

}  // namespace cosmic::idl_detail

// The lexer of the DBC reader (dbc.cpp): cuts a DBC text into tokens, the only place that knows
// about characters, strings spanning lines and CRLF. It streams: one token at a time, with its
// position for located errors. Internal to cosmic_core's DBC reader; a value used by one thread.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/dbc.hpp"

namespace cosmic::dbc_detail {

enum class TokenKind { identifier, number, string, punct, end };

struct Position {
  int line = 1, column = 1;
};

struct Token {
  TokenKind kind = TokenKind::end;
  std::string_view text;  // of a string: what lies between the quotes, escapes as written
  Position at;
  Position past;  // just after the token's last character
  bool first_on_line = false;

  // Keywords and punctuation; a string's content never matches.
  bool is(std::string_view word) const { return kind != TokenKind::string && text == word; }
};

inline bool is_identifier_start(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }
inline bool is_digit(char c) { return c >= '0' && c <= '9'; }
inline bool is_identifier_char(char c) { return is_identifier_start(c) || is_digit(c); }
inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

class Lexer {
 public:
  explicit Lexer(std::string_view text) : text_(text) {}

  // The next token; `end` forever once the text is used up or a string never closes.
  Token next() {
    const bool crossed_line = skip_blanks();
    Token token;
    token.at = here_;
    token.first_on_line = crossed_line || !started_;
    started_ = true;
    if (failure_ || pos_ >= text_.size()) {
      token.past = here_;
      return token;
    }
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '"') {
      read_string(token);
    } else if (is_identifier_start(c)) {
      while (pos_ < text_.size() && is_identifier_char(text_[pos_])) step();
      token.kind = TokenKind::identifier;
    } else if (starts_number()) {
      read_number();
      token.kind = TokenKind::number;
    } else {
      step();
      token.kind = TokenKind::punct;
    }
    if (token.kind != TokenKind::string && token.kind != TokenKind::end) token.text = text_.substr(start, pos_ - start);
    token.past = here_;
    return token;
  }

  const std::optional<DbcError>& failure() const { return failure_; }

 private:
  void step() {
    const bool line_break = text_[pos_++] == '\n';
    here_.line += line_break ? 1 : 0;
    here_.column = line_break ? 1 : here_.column + 1;
  }

  // True when a line break was crossed.
  bool skip_blanks() {
    bool crossed_line = false;
    while (pos_ < text_.size() && is_blank(text_[pos_])) {
      crossed_line = crossed_line || text_[pos_] == '\n';
      step();
    }
    return crossed_line;
  }

  char at(std::size_t offset) const { return pos_ + offset < text_.size() ? text_[pos_ + offset] : '\0'; }

  bool starts_number() const {
    std::size_t offset = (at(0) == '-' || at(0) == '+') ? 1 : 0;
    if (at(offset) == '.') ++offset;
    return is_digit(at(offset));
  }

  // A sign, then digits, letters, '_' and '.', so that "0x1F" or "12abc" stay one (bad) number
  // instead of becoming a number and a name; a sign inside only right after an exponent's 'e'.
  void read_number() {
    if (at(0) == '-' || at(0) == '+') step();
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (!is_identifier_char(c) && c != '.' && !is_exponent_sign()) break;
      step();
    }
  }

  // The number so far has at least one character here: signs only start numbers.
  bool is_exponent_sign() const {
    if (at(0) != '-' && at(0) != '+') return false;
    const char before = text_[pos_ - 1];
    return (before == 'e' || before == 'E') && is_digit(at(1));
  }

  // "...", may span lines; \" and \\ do not end it.
  void read_string(Token& token) {
    step();
    const std::size_t content = pos_;
    while (pos_ < text_.size() && text_[pos_] != '"') {
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) step();
      step();
    }
    if (pos_ >= text_.size()) {
      failure_ =
          DbcError{token.at.line, token.at.column, "unterminated string: no closing '\"' before the end of the text"};
      return;
    }
    token.kind = TokenKind::string;
    token.text = text_.substr(content, pos_ - content);
    step();
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  Position here_;
  bool started_ = false;
  std::optional<DbcError> failure_;
};

}  // namespace cosmic::dbc_detail

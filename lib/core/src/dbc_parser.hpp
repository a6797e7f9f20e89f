// The parser of the DBC reader: walks the statements the lexer (dbc_lexer.hpp) cuts, keeps what
// cosmic/dbc.hpp returns and reports every problem at its line and column. Messages, attributes
// and the cross-references between them live in dbc.cpp; signals (SG_, VAL_, SIG_VALTYPE_) in
// dbc_signals.cpp. It streams: two tokens of look-ahead, never a list of tokens. References between
// statements (duplicate ids and names, BA_ or VAL_ naming an unknown message or signal) are
// resolved once at the end with sorted indexes, never by rescanning, so the whole pass is
// O(n log n). Internal to cosmic_core's DBC reader; a value used by one thread.
#pragma once

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/dbc.hpp"
#include "dbc_lexer.hpp"

namespace cosmic::dbc_detail {

// Keeps the first kDbcMaxReportedErrors, counts the rest, so a file of garbage costs bounded memory.
class ErrorList {
 public:
  void add(Position at, std::string message);
  // In text order (cross-reference errors are found after the parse), then the closing line.
  std::vector<DbcError> finish() &&;

 private:
  std::vector<DbcError> kept_;
  std::size_t unreported_ = 0;
};

// The whole text as a number of type Number (std::from_chars: no sign for unsigned types, no '+').
template <typename Number>
std::optional<Number> parse_whole(std::string_view text) {
  Number value{};
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(text.data(), last, value);
  if (error != std::errc{} || end != last) return std::nullopt;
  return value;
}
inline std::optional<std::uint32_t> parse_uint32(std::string_view text) { return parse_whole<std::uint32_t>(text); }
std::string describe(const Token& token);
std::string describe_id(std::uint32_t raw_id);

struct FoundMessage {
  DbcMessage message;
  std::uint32_t raw_id = 0;
  Position id_at, name_at;
  std::optional<std::uint32_t> explicit_cycle_ms;
  bool duplicate = false;
  bool too_many_signals = false;  // reported once
};

struct CycleTimeValue {
  std::uint32_t raw_id = 0, ms = 0;
  Position id_at;
};

// VAL_ <id> <signal> <value> "<name>" ... ; and SIG_VALTYPE_ <id> <signal> : <1|2> ; name a signal
// that may be declared anywhere in the file: kept until the end.
struct SignalReference {
  std::uint32_t raw_id = 0;
  std::string signal;
  Position at;  // of the message id
};
struct ValueNames {
  SignalReference target;
  std::vector<DbcValueName> names;
};
struct ValueType {
  SignalReference target;
  DbcValueType type = DbcValueType::integer;
};

class Parser {
 public:
  // Braced initializers run in order: the first token, then the second.
  explicit Parser(std::string_view text) : lexer_(text), ahead_{lexer_.next(), lexer_.next()} {}

  DbcFile run() &&;

 private:
  // ---------------------------------------------------------------- the token stream
  const Token& peek(std::size_t k = 0) const { return ahead_[k]; }
  bool at_end() const { return peek().kind == TokenKind::end; }

  Token take() {
    previous_ = ahead_[0];
    ahead_[0] = ahead_[1];
    ahead_[1] = lexer_.next();
    return previous_;
  }

  // A keyword at the beginning of a line starts a statement, and so ends one that lacks its ';'.
  static bool starts_statement(const Token& t) { return t.kind == TokenKind::identifier && t.first_on_line; }
  // Whether `t` still belongs to a statement that ends with ';'.
  static bool in_statement(const Token& t) { return t.kind != TokenKind::end && !starts_statement(t); }
  // Whether `t` still belongs to a statement that ends with its line (BO_, SG_, BU_, ...).
  bool on_same_line(const Token& t) const { return t.kind != TokenKind::end && t.at.line == previous_.past.line; }
  bool line_goes_on_with(TokenKind kind) const { return on_same_line(peek()) && peek().kind == kind; }
  bool line_goes_on_with(std::string_view word) const { return on_same_line(peek()) && peek().is(word); }
  bool statement_goes_on_with(TokenKind kind) const { return in_statement(peek()) && peek().kind == kind; }
  bool statement_goes_on_with(std::string_view word) const { return in_statement(peek()) && peek().is(word); }

  void skip_line() {
    while (on_same_line(peek())) take();
  }
  void skip_statement() {
    while (in_statement(peek())) {
      if (take().is(";")) return;
    }
  }
  void skip_new_symbols();

  // ---------------------------------------------------------------- errors
  void error(Position at, std::string message) { errors_.add(at, std::move(message)); }
  void expected(std::string_view what);
  void fail_line(std::string_view what) {
    expected(what);
    skip_line();
  }
  void fail_statement(std::string_view what) {
    expected(what);
    skip_statement();
  }
  bool expect_semicolon(std::string_view after);

  // ---------------------------------------------------------------- statements (dbc.cpp)
  struct MessageLine {
    Position keyword_at, id_at;
    Token name, length;
    std::uint32_t raw_id = 0;
  };
  void statement(const Token& first);
  void message(const Token& keyword);
  void keep_message(const MessageLine& line);
  bool names_a_frame(const MessageLine& line, std::uint32_t length);
  bool below_message_limit(Position at);
  void attribute_definition();
  void attribute_default();
  void attribute_value();
  std::optional<std::uint32_t> message_id(const Token& id);
  std::optional<std::uint32_t> cycle_time_value();

  // ---------------------------------------------------------------- signals (dbc_signals.cpp)
  void signal(const Token& keyword);
  bool signal_head(DbcSignal& signal);
  bool signal_layout(DbcSignal& signal);
  bool signal_scaling(DbcSignal& signal);
  std::optional<double> number_on_line(std::string_view what);
  bool punct_on_line(std::string_view punct, std::string_view what);
  void keep_signal(DbcSignal signal, Position at);
  void value_names();
  void value_type();
  std::optional<SignalReference> signal_reference(std::string_view keyword);

  // ---------------------------------------------------------------- cross-references
  template <typename Key>
  std::vector<std::size_t> order_by(Key key) const;
  template <typename Key, typename Report>
  void mark_duplicates(Key key, Report report);
  void mark_duplicate_ids();
  void mark_duplicate_names();
  void assign_explicit_cycle_times();
  void settle_cycle_times();
  // dbc_signals.cpp: VAL_ and SIG_VALTYPE_ onto their signals, then what needs the whole message.
  void resolve_signal_references();
  void check_multiplexing(DbcMessage& message);
  DbcSignal* find_signal(const SignalReference& reference, std::string_view keyword);
  bool is_declared_id(std::uint32_t raw_id) const;

  Lexer lexer_;
  std::array<Token, 2> ahead_;
  Token previous_;
  ErrorList errors_;
  bool in_message_ = false;         // SG_ lines may follow
  bool message_kept_ = false;       // ... and belong to found_.back()
  bool too_many_reported_ = false;  // messages in the file
  bool too_many_signals_reported_ = false;
  std::size_t signal_count_ = 0;  // in the whole file
  std::vector<FoundMessage> found_;
  std::vector<std::uint32_t> declared_ids_;  // every BO_ id read, also of messages not kept
  std::vector<CycleTimeValue> cycle_times_;
  std::optional<std::uint32_t> default_cycle_ms_;
  std::vector<ValueNames> value_names_;
  std::vector<ValueType> value_types_;
  // Built by resolve_signal_references(), over the messages kept: raw id -> index in found_, and
  // (raw id, signal name) -> (message, signal).
  std::vector<std::pair<std::uint32_t, std::size_t>> kept_by_id_;
  std::vector<std::pair<std::pair<std::uint32_t, std::string_view>, std::pair<std::size_t, std::size_t>>> signal_index_;
};

}  // namespace cosmic::dbc_detail

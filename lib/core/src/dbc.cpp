// DBC reading (cosmic/dbc.hpp) in two layers: a lexer that cuts the text into tokens
// (dbc_lexer.hpp, the only place that knows about characters, strings spanning lines, CRLF and the
// BOM) and a parser that walks statements (dbc_parser.hpp). This file holds the parser's messages,
// attributes and cross-references; dbc_signals.cpp its signals.
#include "cosmic/dbc.hpp"

#include "cosmic/can_timing.hpp"
#include "dbc_parser.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <numeric>
#include <utility>

namespace cosmic {
namespace dbc_detail {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
constexpr std::string_view kCycleTimeAttribute = "GenMsgCycleTime";
constexpr std::uint32_t kExtendedFlag = 0x8000'0000u;
constexpr std::uint32_t kMaxStandardId = 0x7FFu;
constexpr std::uint32_t kMaxExtendedId = 0x1FFF'FFFFu;
// Vector tools park signals that belong to no message in this pseudo-message; it is never sent.
constexpr std::uint32_t kIndependentSignalsId = 0xC000'0000u;

std::string hex(std::uint32_t value) {
  std::array<char, 8> digits{};
  const auto result = std::to_chars(digits.data(), digits.data() + digits.size(), value, 16);
  std::string out(digits.data(), result.ptr);
  for (char& c : out) c = (c >= 'a' && c <= 'f') ? static_cast<char>(c - 'a' + 'A') : c;
  return "0x" + out;
}

// Why a BO_ id names no CAN frame, or nothing.
std::optional<std::string> id_problem(std::uint32_t raw_id) {
  if ((raw_id & kExtendedFlag) != 0) {
    if ((raw_id & ~kExtendedFlag) <= kMaxExtendedId) return std::nullopt;
    return "extended message id " + std::to_string(raw_id) + " does not fit 29 bits: " + hex(raw_id & ~kExtendedFlag) +
           " > 0x1FFFFFFF after removing bit 31";
  }
  if (raw_id <= kMaxStandardId) return std::nullopt;
  return "standard message id " + describe_id(raw_id) +
         " is above 0x7FF (an extended id has bit 31 set: add 2147483648)";
}

std::optional<std::string> length_problem(std::uint32_t length) {
  if (length > kFdMaxPayload) return "message length " + std::to_string(length) + " is out of range (0..64 bytes)";
  if (!is_frame_length(length, true)) {
    return "message length " + std::to_string(length) + " is not a CAN FD length (0..8, 12, 16, 20, 24, 32, 48 or 64)";
  }
  return std::nullopt;
}

bool is_attribute_object(const Token& t) { return t.is("BU_") || t.is("BO_") || t.is("SG_") || t.is("EV_"); }

}  // namespace

// ------------------------------------------------------------------------------------ shared helpers

void ErrorList::add(Position at, std::string message) {
  if (kept_.size() < kDbcMaxReportedErrors)
    kept_.push_back(DbcError{at.line, at.column, std::move(message)});
  else
    ++unreported_;
}

std::vector<DbcError> ErrorList::finish() && {
  const auto position = [](const DbcError& e) { return std::pair{e.line, e.column}; };
  std::stable_sort(kept_.begin(), kept_.end(), [&](const auto& a, const auto& b) { return position(a) < position(b); });
  if (unreported_ > 0) {
    kept_.push_back(DbcError{0, 0,
                             std::to_string(unreported_) + " more errors not reported (only the first " +
                                 std::to_string(kDbcMaxReportedErrors) + " are)"});
  }
  return std::move(kept_);
}

std::string describe(const Token& token) {
  return token.kind == TokenKind::string ? "the string " + quote_value(token.text) : quote_value(token.text);
}

std::string describe_id(std::uint32_t raw_id) {
  if ((raw_id & kExtendedFlag) != 0) return std::to_string(raw_id) + " (extended " + hex(raw_id & ~kExtendedFlag) + ")";
  return std::to_string(raw_id) + " (" + hex(raw_id) + ")";
}

// ------------------------------------------------------------------------------------ parser

DbcFile Parser::run() && {
  while (!at_end()) statement(take());
  if (lexer_.failure()) errors_.add({lexer_.failure()->line, lexer_.failure()->column}, lexer_.failure()->message);
  mark_duplicate_ids();
  mark_duplicate_names();
  assign_explicit_cycle_times();
  settle_cycle_times();
  resolve_signal_references();
  DbcFile file;
  for (FoundMessage& found : found_) {
    if (!found.duplicate) file.messages.push_back(std::move(found.message));
  }
  file.errors = std::move(errors_).finish();
  return file;
}

// NS_ : and the new symbols' names, one a line, with no terminator: the list ends at the first
// line holding more than one token, as every statement's line does (BS_:, BU_: ..., BO_ ...).
void Parser::skip_new_symbols() {
  while (!at_end()) {
    const Token& t = peek();
    if (t.first_on_line && peek(1).kind != TokenKind::end && peek(1).at.line == t.past.line) return;
    take();
  }
}

// At the next token when it is on the line, else just after the previous token. Silent at an
// end that is an unterminated string: that has its own error, and the rest is unknown.
void Parser::expected(std::string_view what) {
  if (at_end() && lexer_.failure()) return;
  std::string message = "expected " + std::string(what);
  if (on_same_line(peek())) {
    error(peek().at, message + ", found " + describe(peek()));
  } else {
    error(previous_.past, std::move(message));
  }
}

bool Parser::expect_semicolon(std::string_view after) {
  if (peek().is(";")) {
    take();
    return true;
  }
  fail_statement("';' " + std::string(after));
  return false;
}

void Parser::statement(const Token& first) {
  if (first.is("BO_")) return message(first);
  if (first.is("SG_")) return signal(first);
  in_message_ = false;
  if (first.is(";")) return;
  if (first.is("NS_")) return skip_new_symbols();
  if (first.is("VERSION") || first.is("BS_") || first.is("BU_")) return skip_line();
  if (first.is("BA_DEF_")) return attribute_definition();
  if (first.is("BA_DEF_DEF_")) return attribute_default();
  if (first.is("BA_")) return attribute_value();
  if (first.is("VAL_")) return value_names();
  if (first.is("SIG_VALTYPE_")) return value_type();
  // Everything else (CM_, VAL_TABLE_, BO_TX_BU_, EV_, SIG_GROUP_, SG_MUL_VAL_, ..., and what later
  // versions of the format add) carries nothing the gateway needs.
  skip_statement();
}

// BO_ <id> <name>: <length> <transmitter>
void Parser::message(const Token& keyword) {
  in_message_ = true;
  message_kept_ = false;
  if (!line_goes_on_with(TokenKind::number)) return fail_line("the message id (a decimal number) after BO_");
  const Token id = take();
  const auto raw_id = message_id(id);
  if (!raw_id) return skip_line();
  declared_ids_.push_back(*raw_id);
  if (!line_goes_on_with(TokenKind::identifier)) return fail_line("the message name after the id");
  const Token name = take();
  if (!line_goes_on_with(":")) return fail_line("':' after the message name");
  take();
  if (!line_goes_on_with(TokenKind::number)) return fail_line("the message length in bytes after ':'");
  const Token length = take();
  if (!line_goes_on_with(TokenKind::identifier)) return fail_line("the transmitting node after the length");
  take();
  if (on_same_line(peek())) {
    error(peek().at, "unexpected " + describe(peek()) + " after the transmitting node");
    skip_line();
  }
  if (*raw_id != kIndependentSignalsId) keep_message(MessageLine{keyword.at, id.at, name, length, *raw_id});
}

void Parser::keep_message(const MessageLine& line) {
  const auto length = parse_uint32(line.length.text);
  if (!length) {
    return error(line.length.at,
                 "message length " + quote_value(line.length.text) + " is not a whole number of bytes (0..64)");
  }
  if (!names_a_frame(line, *length) || !below_message_limit(line.keyword_at)) return;
  DbcMessage message;
  message.name = std::string(line.name.text);
  message.can_id = line.raw_id & ~kExtendedFlag;
  message.extended = (line.raw_id & kExtendedFlag) != 0;
  message.length = *length;
  message.line = line.keyword_at.line;
  message.column = line.keyword_at.column;
  found_.push_back(FoundMessage{std::move(message), line.raw_id, line.id_at, line.name.at, std::nullopt, false});
  message_kept_ = true;
}

// Reports what is wrong with the id and with the length, both.
bool Parser::names_a_frame(const MessageLine& line, std::uint32_t length) {
  const auto wrong_id = id_problem(line.raw_id);
  const auto wrong_length = length_problem(length);
  if (wrong_id) error(line.id_at, *wrong_id);
  if (wrong_length) error(line.length.at, *wrong_length);
  return !wrong_id && !wrong_length;
}

bool Parser::below_message_limit(Position at) {
  if (found_.size() < kDbcMaxMessages) return true;
  if (!too_many_reported_)
    error(at, "more than " + std::to_string(kDbcMaxMessages) + " messages (the limit of one DBC file)");
  too_many_reported_ = true;
  return false;
}

// BA_DEF_ [BU_|BO_|SG_|EV_] "<name>" <type> [<min> <max> | <enum values>] ;
void Parser::attribute_definition() {
  if (statement_goes_on_with(TokenKind::identifier)) {
    if (!is_attribute_object(peek())) {
      return fail_statement("BU_, BO_, SG_, EV_ or the attribute name as a quoted string after BA_DEF_");
    }
    take();
  }
  if (!statement_goes_on_with(TokenKind::string)) return fail_statement("the attribute name as a quoted string");
  skip_statement();
}

// BA_DEF_DEF_ "<name>" <default value> ;
void Parser::attribute_default() {
  if (!statement_goes_on_with(TokenKind::string))
    return fail_statement("the attribute name as a quoted string after BA_DEF_DEF_");
  if (take().text != kCycleTimeAttribute) return skip_statement();
  const auto ms = cycle_time_value();
  if (!ms) return skip_statement();
  if (expect_semicolon("after the default value")) default_cycle_ms_ = *ms;
}

// BA_ "<name>" [BU_ <node> | BO_ <id> | SG_ <id> <signal> | EV_ <variable>] <value> ;
void Parser::attribute_value() {
  if (!statement_goes_on_with(TokenKind::string))
    return fail_statement("the attribute name as a quoted string after BA_");
  if (take().text != kCycleTimeAttribute) return skip_statement();
  if (!statement_goes_on_with("BO_")) {
    return fail_statement("BO_ and a message id after \"GenMsgCycleTime\" (a message attribute)");
  }
  take();
  if (!statement_goes_on_with(TokenKind::number)) return fail_statement("the message id after BO_");
  const Token id = take();
  const auto raw_id = message_id(id);
  if (!raw_id) return skip_statement();
  const auto ms = cycle_time_value();
  if (!ms) return skip_statement();
  if (expect_semicolon("after the attribute value")) cycle_times_.push_back(CycleTimeValue{*raw_id, *ms, id.at});
}

// The id as BO_ writes it, bit 31 for extended; the range of a CAN id is checked by BO_ alone.
std::optional<std::uint32_t> Parser::message_id(const Token& id) {
  const auto raw_id = parse_uint32(id.text);
  if (!raw_id) error(id.at, "message id " + quote_value(id.text) + " is not a decimal number from 0 to 4294967295");
  return raw_id;
}

// A GenMsgCycleTime value: whole milliseconds, 0 meaning "not cyclic".
std::optional<std::uint32_t> Parser::cycle_time_value() {
  if (!statement_goes_on_with(TokenKind::number)) {
    expected("GenMsgCycleTime in whole milliseconds");
    return std::nullopt;
  }
  const Token value = take();
  if (value.text.front() == '-') {
    error(value.at, "GenMsgCycleTime must not be negative, found " + quote_value(value.text));
    return std::nullopt;
  }
  const auto ms = parse_uint32(value.text);
  if (!ms) {
    error(value.at,
          "GenMsgCycleTime must be a whole number of milliseconds (0..4294967295), found " + quote_value(value.text));
  }
  return ms;
}

// ------------------------------------------------------------------------------------ cross-references

// Indexes of the messages in `found_` ordered by `key`, file order among equals.
template <typename Key>
std::vector<std::size_t> Parser::order_by(Key key) const {
  std::vector<std::size_t> order(found_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return key(found_[a]) < key(found_[b]); });
  return order;
}

// Of several messages with one key the first is kept; each other one is an error, `report`ed
// with the first.
template <typename Key, typename Report>
void Parser::mark_duplicates(Key key, Report report) {
  const auto order = order_by(key);
  std::size_t original = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    FoundMessage& m = found_[order[i]];
    if (i == 0 || key(m) != key(found_[order[i - 1]])) {
      original = order[i];
      continue;
    }
    report(found_[original], m);
    m.duplicate = true;
  }
}

void Parser::mark_duplicate_ids() {
  mark_duplicates([](const FoundMessage& m) { return m.raw_id; },
                  [this](const FoundMessage& first, const FoundMessage& again) {
                    error(again.id_at, "duplicate message id " + describe_id(again.raw_id) + ": " +
                                           quote_value(again.message.name) + " repeats the id of " +
                                           quote_value(first.message.name) + " declared at line " +
                                           std::to_string(first.message.line));
                  });
}

void Parser::mark_duplicate_names() {
  mark_duplicates([](const FoundMessage& m) -> std::string_view { return m.message.name; },
                  [this](const FoundMessage& first, const FoundMessage& again) {
                    error(again.name_at, "duplicate message name " + quote_value(again.message.name) +
                                             ": already declared at line " + std::to_string(first.message.line));
                  });
}

// Explicit BA_ values, the last one for a message winning.
void Parser::assign_explicit_cycle_times() {
  std::vector<std::pair<std::uint32_t, std::size_t>> by_id;  // kept messages: raw id -> index
  for (std::size_t i = 0; i < found_.size(); ++i) {
    if (!found_[i].duplicate) by_id.emplace_back(found_[i].raw_id, i);
  }
  std::sort(by_id.begin(), by_id.end());
  std::sort(declared_ids_.begin(), declared_ids_.end());
  for (const CycleTimeValue& value : cycle_times_) {
    const auto hit = std::lower_bound(by_id.begin(), by_id.end(), std::pair{value.raw_id, std::size_t{0}});
    if (hit != by_id.end() && hit->first == value.raw_id) {
      found_[hit->second].explicit_cycle_ms = value.ms;
    } else if (!is_declared_id(value.raw_id)) {
      error(value.id_at,
            "BA_ \"GenMsgCycleTime\" names message id " + describe_id(value.raw_id) + ", which no BO_ declares");
    }
  }
}

// Needs declared_ids_ sorted (assign_explicit_cycle_times() sorts it).
bool Parser::is_declared_id(std::uint32_t raw_id) const {
  return std::binary_search(declared_ids_.begin(), declared_ids_.end(), raw_id);
}

// The explicit value, else the default; 0 means none.
void Parser::settle_cycle_times() {
  for (FoundMessage& found : found_) {
    const std::optional<std::uint32_t> ms = found.explicit_cycle_ms ? found.explicit_cycle_ms : default_cycle_ms_;
    if (ms && *ms > 0) found.message.cycle_time = std::chrono::duration_cast<Nanos>(std::chrono::milliseconds(*ms));
  }
}

}  // namespace dbc_detail

DbcFile parse_dbc(std::string_view text) {
  if (text.size() > kDbcMaxTextBytes) {
    DbcFile file;
    file.errors.push_back(DbcError{0, 0,
                                   "the DBC text has " + std::to_string(text.size()) +
                                       " bytes, more than the limit of " + std::to_string(kDbcMaxTextBytes) +
                                       " (8 MiB)"});
    return file;
  }
  if (text.starts_with(dbc_detail::kUtf8Bom)) text.remove_prefix(dbc_detail::kUtf8Bom.size());
  return dbc_detail::Parser(text).run();
}

}  // namespace cosmic

// The DBC parser's signals (dbc_parser.hpp): SG_ lines with their layout, scaling, range and unit;
// VAL_ value names and SIG_VALTYPE_ float types, which name their signal by message id and may come
// anywhere in the file, so they are applied once every message is known.
#include "cosmic/dbc_codec.hpp"
#include "dbc_parser.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>
#include <utility>

namespace cosmic::dbc_detail {
namespace {

// "M", "m<n>" or "m<n>M"; nullopt for anything else.
std::optional<std::pair<DbcMultiplex, std::uint32_t>> multiplex_indicator(std::string_view text) {
  if (text == "M") return std::pair{DbcMultiplex::multiplexor, 0u};
  if (text.size() < 2 || text.front() != 'm') return std::nullopt;
  std::string_view digits = text.substr(1);
  DbcMultiplex kind = DbcMultiplex::multiplexed;
  if (digits.back() == 'M') {
    digits.remove_suffix(1);  // extended multiplexing: a multiplexed signal that is a switch itself
    kind = DbcMultiplex::multiplexed_multiplexor;
  }
  const auto value = parse_uint32(digits);
  if (!value) return std::nullopt;
  return std::pair{kind, *value};
}

std::optional<double> parse_double(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(text.data(), last, value);
  if (error != std::errc{} || end != last || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<std::int64_t> parse_int64(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  return parse_whole<std::int64_t>(text);
}

std::string bits_text(const DbcSignal& s) {
  return std::to_string(s.start_bit) + "|" + std::to_string(s.size) + "@" +
         (s.order == DbcByteOrder::big_endian ? "0" : "1") + (s.is_signed ? "-" : "+");
}

}  // namespace

// SG_ <name> [M | m<n> | m<n>M] : <start>|<size>@<order><sign> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
void Parser::signal(const Token& keyword) {
  if (!in_message_) {
    error(keyword.at, "SG_ outside a message: a signal line must follow its BO_ line");
    return skip_line();
  }
  DbcSignal signal;
  signal.line = keyword.at.line;
  signal.column = keyword.at.column;
  if (!signal_head(signal) || !signal_layout(signal) || !signal_scaling(signal)) return skip_line();
  if (!line_goes_on_with(TokenKind::string)) return fail_line("the unit as a quoted string after the range");
  signal.unit = std::string(take().text);
  skip_line();  // the receiving nodes
  keep_signal(std::move(signal), keyword.at);
}

// <name> [indicator] :
bool Parser::signal_head(DbcSignal& signal) {
  if (!line_goes_on_with(TokenKind::identifier)) {
    expected("the signal name after SG_");
    return false;
  }
  signal.name = std::string(take().text);
  if (line_goes_on_with(TokenKind::identifier)) {
    const Token indicator = take();
    const auto multiplex = multiplex_indicator(indicator.text);
    if (!multiplex) {
      error(indicator.at, "expected ':' or a multiplexer indicator (M, m<n> or m<n>M) after the signal name, found " +
                              describe(indicator));
      return false;
    }
    signal.multiplex = multiplex->first;
    signal.multiplex_value = multiplex->second;
    return punct_on_line(":", "':' after the multiplexer indicator");
  }
  return punct_on_line(":", "':' after the signal name");
}

// <start>|<size>@<order><sign>
bool Parser::signal_layout(DbcSignal& signal) {
  if (!line_goes_on_with(TokenKind::number)) {
    expected("the start bit after ':'");
    return false;
  }
  const Token start = take();
  if (!punct_on_line("|", "'|' after the start bit")) return false;
  if (!line_goes_on_with(TokenKind::number)) {
    expected("the signal's size in bits after '|'");
    return false;
  }
  const Token size = take();
  const auto start_bit = parse_uint32(start.text);
  const auto bits = parse_uint32(size.text);
  if (!start_bit || *start_bit > 511) {
    error(start.at, "start bit " + quote_value(start.text) + " is not a bit of a CAN frame (0..511)");
    return false;
  }
  if (!bits || *bits == 0 || *bits > 64) {
    error(size.at, "signal size " + quote_value(size.text) + " is out of range (1..64 bits)");
    return false;
  }
  signal.start_bit = *start_bit;
  signal.size = *bits;
  if (!punct_on_line("@", "'@' after the size")) return false;
  if (!line_goes_on_with("0") && !line_goes_on_with("1")) {
    expected("the byte order after '@': 1 (Intel, little endian) or 0 (Motorola, big endian)");
    return false;
  }
  signal.order = take().is("0") ? DbcByteOrder::big_endian : DbcByteOrder::little_endian;
  if (!line_goes_on_with("+") && !line_goes_on_with("-")) {
    expected("'+' (unsigned) or '-' (signed) after the byte order");
    return false;
  }
  signal.is_signed = take().is("-");
  return true;
}

// (<factor>,<offset>) [<min>|<max>]
bool Parser::signal_scaling(DbcSignal& signal) {
  if (!punct_on_line("(", "'(' and the factor after the sign")) return false;
  const Token factor_token = peek();
  const auto factor = number_on_line("the factor after '('");
  if (!factor || !punct_on_line(",", "',' after the factor")) return false;
  const auto offset = number_on_line("the offset after ','");
  if (!offset || !punct_on_line(")", "')' after the offset")) return false;
  if (*factor == 0.0) {
    error(factor_token.at, "factor 0 maps every raw value to the offset: a signal's factor must not be 0");
    return false;
  }
  if (!punct_on_line("[", "'[' and the minimum after the scaling")) return false;
  const Token minimum_token = peek();
  const auto minimum = number_on_line("the minimum after '['");
  if (!minimum || !punct_on_line("|", "'|' after the minimum")) return false;
  const auto maximum = number_on_line("the maximum after '|'");
  if (!maximum || !punct_on_line("]", "']' after the maximum")) return false;
  if (*minimum > *maximum) {
    error(minimum_token.at, "the minimum " + quote_value(minimum_token.text) + " is above the maximum");
    return false;
  }
  signal.factor = *factor;
  signal.offset = *offset;
  signal.minimum = *minimum;
  signal.maximum = *maximum;
  return true;
}

std::optional<double> Parser::number_on_line(std::string_view what) {
  if (!line_goes_on_with(TokenKind::number)) {
    expected(what);
    return std::nullopt;
  }
  const Token number = take();
  const auto value = parse_double(number.text);
  if (!value) error(number.at, quote_value(number.text) + " is not a finite decimal number");
  return value;
}

bool Parser::punct_on_line(std::string_view punct, std::string_view what) {
  if (!line_goes_on_with(punct)) {
    expected(what);
    return false;
  }
  take();
  return true;
}

void Parser::keep_signal(DbcSignal signal, Position at) {
  if (!message_kept_) return;  // the message's own error says why
  DbcMessage& message = found_.back().message;
  if (!dbc_signal_fits(signal, message.length)) {
    return error(at, "signal " + quote_value(signal.name) + " (" + bits_text(signal) + ") does not fit the " +
                         std::to_string(message.length) + " bytes of message " + quote_value(message.name));
  }
  if (message.signals.size() >= kDbcMaxSignalsPerMessage) {
    if (!found_.back().too_many_signals) {
      error(at, "more than " + std::to_string(kDbcMaxSignalsPerMessage) + " signals in message " +
                    quote_value(message.name) + " (the limit of one message)");
    }
    found_.back().too_many_signals = true;
    return;
  }
  if (signal_count_ >= kDbcMaxSignals) {
    if (!too_many_signals_reported_)
      error(at, "more than " + std::to_string(kDbcMaxSignals) + " signals (the limit of one DBC file)");
    too_many_signals_reported_ = true;
    return;
  }
  ++signal_count_;
  message.signals.push_back(std::move(signal));
}

// VAL_ <message id> <signal> { <raw value> "<name>" } ;  (VAL_ <environment variable> ... ; is skipped)
void Parser::value_names() {
  if (statement_goes_on_with(TokenKind::identifier)) return skip_statement();
  const auto target = signal_reference("VAL_");
  if (!target) return skip_statement();
  ValueNames names{*target, {}};
  while (statement_goes_on_with(TokenKind::number)) {
    const Token value_token = take();
    const auto value = parse_int64(value_token.text);
    if (!value) {
      error(value_token.at, "VAL_ value " + quote_value(value_token.text) + " is not a whole raw value");
      return skip_statement();
    }
    if (!statement_goes_on_with(TokenKind::string)) return fail_statement("the value's name as a quoted string");
    const Token name = take();
    if (names.names.size() >= kDbcMaxValueNames) {
      error(value_token.at, "more than " + std::to_string(kDbcMaxValueNames) + " value names for one signal");
      return skip_statement();
    }
    names.names.push_back(DbcValueName{*value, std::string(name.text)});
  }
  if (expect_semicolon("after the value names")) value_names_.push_back(std::move(names));
}

// SIG_VALTYPE_ <message id> <signal> [:] <0|1|2> ;
void Parser::value_type() {
  const auto target = signal_reference("SIG_VALTYPE_");
  if (!target) return skip_statement();
  if (statement_goes_on_with(":")) take();
  if (!statement_goes_on_with("0") && !statement_goes_on_with("1") && !statement_goes_on_with("2")) {
    return fail_statement("the value type: 0 (integer), 1 (IEEE float, 32 bits) or 2 (IEEE double, 64 bits)");
  }
  const Token type = take();
  const DbcValueType value_type =
      type.is("1") ? DbcValueType::float32 : (type.is("2") ? DbcValueType::float64 : DbcValueType::integer);
  if (expect_semicolon("after the value type")) value_types_.push_back(ValueType{*target, value_type});
}

// <message id> <signal name>
std::optional<SignalReference> Parser::signal_reference(std::string_view keyword) {
  if (!statement_goes_on_with(TokenKind::number)) {
    expected("the message id after " + std::string(keyword));
    return std::nullopt;
  }
  const Token id = take();
  const auto raw_id = message_id(id);
  if (!raw_id) return std::nullopt;
  if (!statement_goes_on_with(TokenKind::identifier)) {
    expected("the signal name after the message id");
    return std::nullopt;
  }
  return SignalReference{*raw_id, std::string(take().text), id.at};
}

// ------------------------------------------------------------------------------------ cross-references

void Parser::resolve_signal_references() {
  for (std::size_t m = 0; m < found_.size(); ++m) {
    if (found_[m].duplicate) continue;
    kept_by_id_.emplace_back(found_[m].raw_id, m);
    const auto& signals = found_[m].message.signals;
    for (std::size_t s = 0; s < signals.size(); ++s)
      signal_index_.push_back({{found_[m].raw_id, signals[s].name}, {m, s}});
  }
  std::sort(kept_by_id_.begin(), kept_by_id_.end());
  std::stable_sort(signal_index_.begin(), signal_index_.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<std::size_t, std::size_t>> repeated;  // (message, signal) to drop
  for (std::size_t i = 1; i < signal_index_.size(); ++i) {
    if (signal_index_[i].first != signal_index_[i - 1].first) continue;
    const auto [m, s] = signal_index_[i].second;
    const DbcSignal& again = found_[m].message.signals[s];
    error({again.line, again.column},
          "duplicate signal name " + quote_value(again.name) + " in message " + quote_value(found_[m].message.name));
    repeated.push_back({m, s});
  }
  for (ValueNames& names : value_names_) {
    DbcSignal* signal = find_signal(names.target, "VAL_");
    if (signal == nullptr) continue;
    std::stable_sort(names.names.begin(), names.names.end(),
                     [](const DbcValueName& a, const DbcValueName& b) { return a.value < b.value; });
    const auto twice = std::adjacent_find(names.names.begin(), names.names.end(),
                                          [](const auto& a, const auto& b) { return a.value == b.value; });
    if (twice != names.names.end()) {
      error(names.target.at, "VAL_ names raw value " + std::to_string(twice->value) + " of signal " +
                                 quote_value(signal->name) + " twice");
      continue;
    }
    signal->value_names = std::move(names.names);
  }
  for (const ValueType& type : value_types_) {
    DbcSignal* signal = find_signal(type.target, "SIG_VALTYPE_");
    if (signal == nullptr) continue;
    const std::uint32_t needed =
        type.type == DbcValueType::float32 ? 32 : (type.type == DbcValueType::float64 ? 64 : 0);
    if (needed != 0 && signal->size != needed) {
      error(type.target.at, "SIG_VALTYPE_ makes signal " + quote_value(signal->name) + " an IEEE float of " +
                                std::to_string(needed) + " bits, but it has " + std::to_string(signal->size));
      continue;
    }
    signal->value_type = type.type;
  }
  // Drop repeated signals last to first, so the indexes left stay valid.
  std::sort(repeated.begin(), repeated.end(), std::greater<>{});
  for (const auto& [m, s] : repeated) {
    auto& signals = found_[m].message.signals;
    signals.erase(signals.begin() + static_cast<std::ptrdiff_t>(s));
  }
  for (FoundMessage& found : found_) {
    if (!found.duplicate) check_multiplexing(found.message);
  }
}

// One switch at most; a multiplexed signal needs one. What breaks the rule is reported and dropped,
// so that what the file returns reads back as it is.
void Parser::check_multiplexing(DbcMessage& message) {
  const auto is_switch = [](const DbcSignal& s) { return s.multiplex == DbcMultiplex::multiplexor; };
  const auto first_switch = std::find_if(message.signals.begin(), message.signals.end(), is_switch);
  if (first_switch != message.signals.end()) {
    const std::string first = first_switch->name;
    std::erase_if(message.signals, [&](const DbcSignal& s) {
      if (!is_switch(s) || s.name == first) return false;
      error({s.line, s.column}, "message " + quote_value(message.name) + " has a second multiplexor switch " +
                                    quote_value(s.name) + " (the first is " + quote_value(first) + ")");
      return true;
    });
    return;
  }
  std::erase_if(message.signals, [&](const DbcSignal& s) {
    if (s.multiplex != DbcMultiplex::multiplexed && s.multiplex != DbcMultiplex::multiplexed_multiplexor) return false;
    error({s.line, s.column}, "signal " + quote_value(s.name) + " is multiplexed, but message " +
                                  quote_value(message.name) + " has no multiplexor switch (M)");
    return true;
  });
}

DbcSignal* Parser::find_signal(const SignalReference& reference, std::string_view keyword) {
  const auto key = std::pair<std::uint32_t, std::string_view>{reference.raw_id, reference.signal};
  const auto hit = std::lower_bound(signal_index_.begin(), signal_index_.end(), key,
                                    [](const auto& entry, const auto& k) { return entry.first < k; });
  if (hit != signal_index_.end() && hit->first == key) {
    return &found_[hit->second.first].message.signals[hit->second.second];
  }
  if (!is_declared_id(reference.raw_id)) {
    error(reference.at,
          std::string(keyword) + " names message id " + describe_id(reference.raw_id) + ", which no BO_ declares");
    return nullptr;
  }
  const auto message = std::lower_bound(kept_by_id_.begin(), kept_by_id_.end(),
                                        std::pair<std::uint32_t, std::size_t>{reference.raw_id, 0});
  if (message != kept_by_id_.end() && message->first == reference.raw_id) {
    error(reference.at, std::string(keyword) + " names signal " + quote_value(reference.signal) + ", which message " +
                            quote_value(found_[message->second].message.name) + " does not declare");
  }
  return nullptr;  // a message declared but not kept has its own error
}

}  // namespace cosmic::dbc_detail

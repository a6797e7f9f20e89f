// A DBC file as the configuration loader reads one for a CAN bus's background traffic or a typed
// channel (cosmic::parse_dbc): any bytes must end in messages and/or located errors, never a crash.
// Every message returned names a real CAN frame and every signal fits it; the messages and their
// signals survive being written back as DBC and read again; CRLF line endings and a BOM change
// neither the messages nor where errors are. The codec (cosmic/dbc_codec.hpp) reads each signal of
// a frame made of the input's first bytes and writes it back to the same bits, and a message's type
// (cosmic/dbc_type.hpp) is either refused with located errors or a sound type.
#include <algorithm>
#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <utility>

#include "cosmic/dbc.hpp"
#include "cosmic/dbc_codec.hpp"
#include "cosmic/dbc_type.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

constexpr std::uint32_t kExtendedFlag = 0x8000'0000u;

int line_count(std::string_view text) {
  int lines = 1;
  for (const char c : text) lines += c == '\n' ? 1 : 0;
  return lines;
}

void check_message(const cosmic::DbcMessage& m) {
  require(!m.name.empty());
  require(m.extended ? m.can_id <= 0x1FFF'FFFFu : m.can_id <= 0x7FFu);
  require(m.length <= 8 || m.length == 12 || m.length == 16 || m.length == 20 || m.length == 24 || m.length == 32 ||
          m.length == 48 || m.length == 64);
  require(m.line >= 1 && m.column >= 1);
  if (m.cycle_time) require(m.cycle_time->count() > 0 && m.cycle_time->count() % 1'000'000 == 0);
  require(m.signals.size() <= cosmic::kDbcMaxSignalsPerMessage);
  std::set<std::string> names;
  int switches = 0;
  for (const cosmic::DbcSignal& s : m.signals) {
    require(names.insert(s.name).second);
    require(s.size >= 1 && s.size <= 64 && cosmic::dbc_signal_fits(s, m.length));
    require(s.factor != 0.0 && s.minimum <= s.maximum);
    if (s.value_type == cosmic::DbcValueType::float32) require(s.size == 32);
    if (s.value_type == cosmic::DbcValueType::float64) require(s.size == 64);
    require(s.value_names.size() <= cosmic::kDbcMaxValueNames);
    for (std::size_t i = 1; i < s.value_names.size(); ++i) require(s.value_names[i - 1].value < s.value_names[i].value);
    switches += s.multiplex == cosmic::DbcMultiplex::multiplexor ? 1 : 0;
  }
  require(switches <= 1);
}

void check_messages(const cosmic::DbcFile& file) {
  require(file.messages.size() <= cosmic::kDbcMaxMessages);
  std::set<std::pair<std::uint32_t, bool>> ids;
  std::set<std::string> names;
  std::pair<int, int> previous{0, 0};
  for (const auto& m : file.messages) {
    check_message(m);
    require(ids.insert({m.can_id, m.extended}).second);
    require(names.insert(m.name).second);
    require(std::pair{m.line, m.column} > previous);  // file order
    previous = {m.line, m.column};
  }
}

void check_errors(const cosmic::DbcFile& file, int lines) {
  require(file.ok() == file.errors.empty());
  require(file.errors.size() <= cosmic::kDbcMaxReportedErrors + 1);
  for (std::size_t i = 0; i < file.errors.size(); ++i) {
    const cosmic::DbcError& e = file.errors[i];
    require(!e.message.empty() && e.message.size() < 400);
    if (e.line == 0) {
      // Only the closing count of unreported errors (a too long text cannot be fuzzed here).
      require(e.column == 0 && i == cosmic::kDbcMaxReportedErrors);
    } else {
      require(e.line <= lines && e.column >= 1);
    }
  }
}

std::string number(double value) { return cosmic::shortest_number_text(value); }

std::string multiplex_text(const cosmic::DbcSignal& s) {
  switch (s.multiplex) {
    case cosmic::DbcMultiplex::none:
      return "";
    case cosmic::DbcMultiplex::multiplexor:
      return " M";
    case cosmic::DbcMultiplex::multiplexed:
      return " m" + std::to_string(s.multiplex_value);
    case cosmic::DbcMultiplex::multiplexed_multiplexor:
      return " m" + std::to_string(s.multiplex_value) + "M";
  }
  return "";
}

// One SG_ line; VAL_ and SIG_VALTYPE_ statements go to `after`.
std::string signal_text(const cosmic::DbcSignal& s, const std::string& id, std::string& after) {
  std::string text = " SG_ " + s.name + multiplex_text(s) + " : " + std::to_string(s.start_bit) + "|" +
                     std::to_string(s.size) + "@" + (s.order == cosmic::DbcByteOrder::big_endian ? "0" : "1") +
                     (s.is_signed ? "-" : "+") + " (" + number(s.factor) + "," + number(s.offset) + ") [" +
                     number(s.minimum) + "|" + number(s.maximum) + "] \"" + s.unit + "\" X\n";
  if (!s.value_names.empty()) {
    after += "VAL_ " + id + " " + s.name;
    for (const auto& v : s.value_names) after += " " + std::to_string(v.value) + " \"" + v.name + "\"";
    after += " ;\n";
  }
  if (s.value_type != cosmic::DbcValueType::integer)
    after += "SIG_VALTYPE_ " + id + " " + s.name + " : " + (s.value_type == cosmic::DbcValueType::float32 ? "1" : "2") +
             ";\n";
  return text;
}

// The messages written back as the smallest DBC that declares them.
std::string to_dbc(const cosmic::DbcFile& file) {
  std::string text = "VERSION \"\"\nBU_: X\n";
  std::string attributes;
  for (const auto& m : file.messages) {
    const std::string id = std::to_string(m.can_id | (m.extended ? kExtendedFlag : 0));
    text += "BO_ " + id + " " + m.name + ": " + std::to_string(m.length) + " X\n";
    for (const auto& s : m.signals) text += signal_text(s, id, attributes);
    if (m.cycle_time)
      attributes +=
          "BA_ \"GenMsgCycleTime\" BO_ " + id + " " + std::to_string(m.cycle_time->count() / 1'000'000) + ";\n";
  }
  return text + attributes;
}

bool same_signals(const cosmic::DbcMessage& a, const cosmic::DbcMessage& b) {
  if (a.signals.size() != b.signals.size()) return false;
  for (std::size_t i = 0; i < a.signals.size(); ++i) {
    const auto& x = a.signals[i];
    const auto& y = b.signals[i];
    if (x.name != y.name || x.start_bit != y.start_bit || x.size != y.size || x.order != y.order ||
        x.is_signed != y.is_signed || x.value_type != y.value_type || x.factor != y.factor || x.offset != y.offset ||
        x.minimum != y.minimum || x.maximum != y.maximum || x.unit != y.unit || x.multiplex != y.multiplex ||
        x.multiplex_value != y.multiplex_value || x.value_names != y.value_names)
      return false;
  }
  return true;
}

// Each signal of a frame made of `bytes` read, written into a blank frame and read again: the
// same bits; an unscaled integer signal's physical value gives back its bits. A type from the
// message is refused with located errors or sound.
void check_codec_and_type(const cosmic::DbcMessage& m, std::string_view bytes) {
  std::array<std::uint8_t, 64> frame{};
  std::copy_n(bytes.begin(), std::min(bytes.size(), std::size_t{m.length}), frame.begin());
  const std::span<const std::uint8_t> data(frame.data(), m.length);
  for (const cosmic::DbcSignal& s : m.signals) {
    const std::uint64_t bits = cosmic::dbc_read_bits(s, data);
    require(s.size == 64 || bits >> s.size == 0);
    std::array<std::uint8_t, 64> blank{};
    cosmic::dbc_write_bits(s, bits, std::span<std::uint8_t>(blank.data(), m.length));
    require(cosmic::dbc_read_bits(s, std::span<const std::uint8_t>(blank.data(), m.length)) == bits);
    const bool exact =
        s.value_type == cosmic::DbcValueType::integer && s.factor == 1.0 && s.offset == 0.0 && s.size <= 53;
    if (exact) require(cosmic::dbc_bits_for(s, cosmic::dbc_physical(s, bits)) == bits);
    (void)cosmic::dbc_signal_present(m, s, data);
    (void)cosmic::dbc_saturated_bits_for(s, cosmic::dbc_physical(s, bits) * 3.0);
  }
  const cosmic::DbcChannelType typed = cosmic::channel_type_from_dbc(m);
  if (typed.ok()) {
    require(typed.type.fields.size() == m.signals.size() && cosmic::check_type(typed.type).empty());
  } else {
    for (const auto& e : typed.errors) require(e.line >= 1 && e.column >= 1 && !e.message.empty());
  }
}

void check_round_trip(const cosmic::DbcFile& file) {
  const cosmic::DbcFile again = cosmic::parse_dbc(to_dbc(file));
  require(again.ok() && again.messages.size() == file.messages.size());
  for (std::size_t i = 0; i < file.messages.size(); ++i) {
    const auto& a = file.messages[i];
    const auto& b = again.messages[i];
    require(a.name == b.name && a.can_id == b.can_id && a.extended == b.extended && a.length == b.length &&
            a.cycle_time == b.cycle_time && same_signals(a, b));
  }
}

std::string with_crlf(std::string_view text) {
  std::string out;
  out.reserve(text.size() * 2);
  for (const char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

// Same messages, same error locations (messages may quote a string that now holds a '\r').
void require_same_outcome(const cosmic::DbcFile& a, const cosmic::DbcFile& b) {
  require(a.messages.size() == b.messages.size() && a.errors.size() == b.errors.size());
  for (std::size_t i = 0; i < a.messages.size(); ++i) {
    const auto& x = a.messages[i];
    const auto& y = b.messages[i];
    require(x.name == y.name && x.can_id == y.can_id && x.extended == y.extended && x.length == y.length &&
            x.cycle_time == y.cycle_time && x.line == y.line && x.column == y.column);
  }
  for (std::size_t i = 0; i < a.errors.size(); ++i) {
    require(a.errors[i].line == b.errors[i].line && a.errors[i].column == b.errors[i].column);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const cosmic::DbcFile file = cosmic::parse_dbc(text);
  check_messages(file);
  check_errors(file, line_count(text));
  check_round_trip(file);
  for (const auto& m : file.messages) check_codec_and_type(m, text);
  if (text.size() * 2 <= cosmic::kDbcMaxTextBytes && !text.starts_with("\xEF\xBB\xBF")) {
    require_same_outcome(file, cosmic::parse_dbc(with_crlf(text)));
    require_same_outcome(file, cosmic::parse_dbc("\xEF\xBB\xBF" + std::string(text)));
  }
  return 0;
}

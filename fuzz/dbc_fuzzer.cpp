// A DBC file as the configuration loader reads one for a CAN bus's background traffic
// (cosmic::parse_dbc): any bytes must end in messages and/or located errors, never a crash.
// Every message returned names a real CAN frame; the messages survive being written back as DBC
// and read again; CRLF line endings and a BOM change neither the messages nor where errors are.
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <utility>

#include "cosmic/dbc.hpp"
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

// The messages written back as the smallest DBC that declares them.
std::string to_dbc(const cosmic::DbcFile& file) {
  std::string text = "VERSION \"\"\nBU_: X\n";
  std::string attributes;
  for (const auto& m : file.messages) {
    const std::string id = std::to_string(m.can_id | (m.extended ? kExtendedFlag : 0));
    text += "BO_ " + id + " " + m.name + ": " + std::to_string(m.length) + " X\n";
    if (m.cycle_time)
      attributes +=
          "BA_ \"GenMsgCycleTime\" BO_ " + id + " " + std::to_string(m.cycle_time->count() / 1'000'000) + ";\n";
  }
  return text + attributes;
}

void check_round_trip(const cosmic::DbcFile& file) {
  const cosmic::DbcFile again = cosmic::parse_dbc(to_dbc(file));
  require(again.ok() && again.messages.size() == file.messages.size());
  for (std::size_t i = 0; i < file.messages.size(); ++i) {
    const auto& a = file.messages[i];
    const auto& b = again.messages[i];
    require(a.name == b.name && a.can_id == b.can_id && a.extended == b.extended && a.length == b.length &&
            a.cycle_time == b.cycle_time);
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
  if (text.size() * 2 <= cosmic::kDbcMaxTextBytes && !text.starts_with("\xEF\xBB\xBF")) {
    require_same_outcome(file, cosmic::parse_dbc(with_crlf(text)));
    require_same_outcome(file, cosmic::parse_dbc("\xEF\xBB\xBF" + std::string(text)));
  }
  return 0;
}

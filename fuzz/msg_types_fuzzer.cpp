// ROS 2 .msg files as a typed channel's `type: {msg: FILE, name: pkg/msg/Name}` names them
// (cosmic::parse_msg and cosmic::msg_channel_type, cosmic/msg_types.hpp). The input is up to four
// messages p/msg/A..D, separated by lines "---" (A may use B, C, D, itself, and the built-in
// builtin_interfaces types). Any bytes end in fields and/or located errors, never a crash: every
// error of a file lies within that file's text; a file without errors keeps the limits, its names
// and bounds are valid, and written back as .msg text it reads back to the same fields, constants
// and units. A's type is refused with errors naming the file they are in, or passes check_type.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/msg_types.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

// The lengths of the text's lines ('\n'-separated), to check where errors point.
std::vector<std::size_t> line_lengths(std::string_view text) {
  std::vector<std::size_t> lengths{0};
  for (const char c : text) {
    if (c == '\n') {
      lengths.push_back(0);
    } else {
      ++lengths.back();
    }
  }
  return lengths;
}

void require_located(const std::vector<std::size_t>& lines, int line, int column) {
  if (line == 0) return;  // the text's size, the closing count, a problem of no line
  require(line >= 1 && static_cast<std::size_t>(line) <= lines.size() && column >= 1);
  require(static_cast<std::size_t>(column) <= lines[static_cast<std::size_t>(line) - 1] + 1);
}

std::string type_text(const cosmic::MsgFieldType& t) {
  std::string out = t.package.empty() ? t.name : t.package + "/" + t.name;
  if (t.string_bound != 0) out += "<=" + std::to_string(t.string_bound);
  switch (t.array) {
    case cosmic::MsgFieldType::Array::none:
      break;
    case cosmic::MsgFieldType::Array::fixed:
      out += "[" + std::to_string(t.array_size) + "]";
      break;
    case cosmic::MsgFieldType::Array::bounded:
      out += "[<=" + std::to_string(t.array_size) + "]";
      break;
    case cosmic::MsgFieldType::Array::unbounded:
      out += "[]";
      break;
  }
  return out;
}

// The file as .msg text again: one definition a line, a unit in a comment of its own line.
std::string to_msg(const cosmic::MsgFile& file) {
  std::string text;
  for (const auto& c : file.constants) text += c.type + " " + c.name + "=" + c.value + "\n";
  for (const auto& f : file.fields) {
    text += type_text(f.type) + " " + f.name + (f.default_value ? " " + *f.default_value : "");
    if (!f.unit.empty() && f.unit.find('\n') == std::string::npos) text += " # [" + f.unit + "]";
    text += "\n";
  }
  return text;
}

void check_file(std::string_view text) {
  const cosmic::MsgFile file = cosmic::parse_msg(text);
  const auto lines = line_lengths(text);
  require(file.errors.size() <= 101);
  for (const auto& e : file.errors) {
    require(!e.message.empty());
    require_located(lines, e.line, e.column);
  }
  if (!file.ok()) return;
  require(file.fields.size() <= cosmic::kMsgMaxFields && file.constants.size() <= cosmic::kMsgMaxConstants);
  for (const auto& f : file.fields) {
    require(cosmic::valid_field_name(f.name) || f.name.size() > 64);
    require(f.type.string_bound <= cosmic::kMaxTypeBound && f.type.array_size <= cosmic::kMaxTypeBound);
    require((f.type.array_size == 0) == (f.type.array == cosmic::MsgFieldType::Array::none ||
                                         f.type.array == cosmic::MsgFieldType::Array::unbounded));
  }
  const cosmic::MsgFile again = cosmic::parse_msg(to_msg(file));
  require(again.ok() && again.fields.size() == file.fields.size() && again.constants.size() == file.constants.size());
  for (std::size_t i = 0; i < file.fields.size(); ++i) {
    const auto& a = file.fields[i];
    const auto& b = again.fields[i];
    require(a.name == b.name && a.type == b.type && a.default_value == b.default_value);
    if (a.unit.find('\n') == std::string::npos) require(a.unit == b.unit);
  }
  for (std::size_t i = 0; i < file.constants.size(); ++i) {
    require(file.constants[i].name == again.constants[i].name && file.constants[i].value == again.constants[i].value);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::map<std::string, std::string> texts;  // "A".."D"
  std::size_t start = 0;
  for (const char* name : {"A", "B", "C", "D"}) {
    const std::size_t end = input.find("\n---\n", start);
    texts[name] = std::string(input.substr(start, end == std::string_view::npos ? input.npos : end - start));
    check_file(texts[name]);
    if (end == std::string_view::npos) break;
    start = end + 5;
  }
  const cosmic::MsgLoader load = [&](const std::string& package,
                                     const std::string& name) -> std::optional<std::string> {
    const auto it = texts.find(name);
    if (package != "p" || it == texts.end()) return std::nullopt;
    return it->second;
  };
  // Unbounded sequences of A bounded by its first byte, so that a big type can pass check_type.
  std::map<std::string, std::uint32_t> max_length;
  for (const auto& f : cosmic::parse_msg(texts["A"]).fields) {
    if (f.type.array == cosmic::MsgFieldType::Array::unbounded) max_length[f.name] = 1 + (size > 0 ? data[0] : 0);
  }
  const cosmic::MsgChannelType typed = cosmic::msg_channel_type("p", "A", load, max_length);
  if (typed.ok()) require(cosmic::check_type(typed.type).empty() && !typed.type.fields.empty());
  require(typed.ok() || !typed.errors.empty());
  require(!typed.files.empty() || !typed.ok());
  for (const auto& e : typed.errors) {
    require(!e.message.empty());
    if (e.file.size() < 8 || e.file.substr(0, 6) != "p/msg/" || e.line == 0) continue;
    const auto it = texts.find(e.file.substr(6));
    require(it != texts.end());
    require_located(line_lengths(it->second), e.line, e.column);
  }
  return 0;
}

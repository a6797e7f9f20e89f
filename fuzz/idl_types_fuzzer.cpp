// OMG IDL type files as a typed channel's `type: {idl: FILE, ...}` names them
// (cosmic::parse_idl_types, cosmic/idl_types.hpp). The input is the file, then after each NUL byte
// one more file, served by the loader to the i-th distinct name an #include asks for. Any bytes
// end in declarations and/or located errors, never a crash: every error lies within the file it
// names. A set without errors keeps the limits; every struct's type is refused with located errors
// or passes check_type; the declarations written back as one IDL text (each in its modules, names
// escaped, references absolute) read back equal.
#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/idl_types.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

int idl_line_count(std::string_view text) {
  int lines = 1;
  for (const char c : text) lines += c == '\n' ? 1 : 0;
  return lines;
}

// --- writing declarations back as IDL ---

std::string escaped_name(std::string_view scoped) {
  std::string out = "::_";
  for (std::size_t i = 0; i < scoped.size(); ++i) {
    if (scoped.substr(i, 2) == "::") {
      out += "::_";
      ++i;
    } else {
      out += scoped[i];
    }
  }
  return out;
}

std::string last_part(std::string_view scoped) {
  const auto at = scoped.rfind("::");
  return "_" + std::string(at == std::string_view::npos ? scoped : scoped.substr(at + 2));
}

// "module _a { module _b { " and its closing, for a declaration's scoped name.
std::pair<std::string, std::string> modules_of(std::string_view scoped) {
  std::string open, close;
  for (auto at = scoped.find("::"); at != std::string_view::npos; at = scoped.find("::")) {
    open += "module _" + std::string(scoped.substr(0, at)) + " { ";
    close += "}; ";
    scoped.remove_prefix(at + 2);
  }
  return {open, close};
}

std::string quoted(std::string_view text) {
  static const char* const kHex = "0123456789abcdef";
  std::string out = "\"";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string type_text(const cosmic::IdlType& t) {
  using Kind = cosmic::IdlType::Kind;
  switch (t.kind) {
    case Kind::primitive:
      return t.name;
    case Kind::string:
      return t.bound == 0 ? "string" : "string<" + std::to_string(t.bound) + ">";
    case Kind::sequence:
      return "sequence<" + type_text(t.element.at(0)) + (t.bound == 0 ? "" : ", " + std::to_string(t.bound)) + ">";
    default:
      return escaped_name(t.name);
  }
}

std::string dimensions_text(const std::vector<std::uint32_t>& dimensions) {
  std::string out;
  for (const std::uint32_t d : dimensions) out += "[" + std::to_string(d) + "]";
  return out;
}

std::string member_text(const cosmic::IdlMember& m) {
  std::string out;
  if (!m.unit.empty()) out += "@unit(" + quoted(m.unit) + ") ";
  if (m.minimum) out += "@min(" + cosmic::shortest_number_text(*m.minimum) + ") ";
  if (m.maximum) out += "@max(" + cosmic::shortest_number_text(*m.maximum) + ") ";
  return out + type_text(m.type) + " _" + m.name + dimensions_text(m.dimensions) + "; ";
}

std::string struct_text(const cosmic::IdlStruct& s) {
  std::string out;
  if (s.extensibility_declared)
    out += s.extensibility == cosmic::CdrExtensibility::appendable ? "@appendable " : "@final ";
  out += "struct " + last_part(s.name) + " { ";
  for (const auto& m : s.members) out += member_text(m);
  return out + "}; ";
}

std::string enum_text(const cosmic::IdlEnum& e) {
  std::string out = "enum " + last_part(e.name) + " { ";
  for (std::size_t i = 0; i < e.values.size(); ++i) {
    out += (i ? ", @value(" : "@value(") + std::to_string(e.values[i].value) + ") _" + e.values[i].name;
  }
  return out + " }; ";
}

std::string constant_text(const cosmic::IdlConstant& c) {
  const bool text = c.type.kind == cosmic::IdlType::Kind::string;
  return "const " + type_text(c.type) + " " + last_part(c.name) + " = " + (text ? quoted(c.value) : c.value) + "; ";
}

std::string wrapped(std::string_view scoped, const std::string& declaration) {
  const auto [open, close] = modules_of(scoped);
  return open + declaration + close + "\n";
}

// The declarations this one's type refers to.
void referenced(const cosmic::IdlType& t, std::vector<std::string>& out) {
  if (t.kind == cosmic::IdlType::Kind::structure || t.kind == cosmic::IdlType::Kind::alias) out.push_back(t.name);
  for (const auto& e : t.element) referenced(e, out);
}

// Every declaration in an order that declares before use (enums and constants need nothing).
std::string to_idl(const cosmic::IdlTypeFile& file) {
  std::string text;
  for (const auto& e : file.enums) text += wrapped(e.name, enum_text(e));
  for (const auto& c : file.constants) text += wrapped(c.name, constant_text(c));
  std::vector<std::pair<std::string, std::string>> pending;  // name, text
  std::map<std::string, std::vector<std::string>> needs;
  for (const auto& s : file.structs) {
    pending.emplace_back(s.name, wrapped(s.name, struct_text(s)));
    for (const auto& m : s.members) referenced(m.type, needs[s.name]);
  }
  for (const auto& t : file.typedefs) {
    pending.emplace_back(t.name, wrapped(t.name, "typedef " + type_text(t.type) + " " + last_part(t.name) +
                                                     dimensions_text(t.dimensions) + "; "));
    referenced(t.type, needs[t.name]);
  }
  std::map<std::string, bool> done;
  for (bool progress = true; progress;) {
    progress = false;
    for (const auto& [name, declaration] : pending) {
      if (done[name]) continue;
      const auto& wanted = needs[name];
      if (!std::all_of(wanted.begin(), wanted.end(), [&done](const std::string& n) { return done[n]; })) continue;
      text += declaration;
      done[name] = progress = true;
    }
  }
  return text;
}

// What the text says of the types, without where and how it said it.
cosmic::IdlTypeFile types_only(cosmic::IdlTypeFile file) {
  file.includes.clear();
  for (auto& s : file.structs) {
    s.file.clear(), s.comment.clear(), s.line = s.column = 0;
    for (auto& m : s.members) m.default_value.clear(), m.comment.clear(), m.line = m.column = 0;
  }
  for (auto& e : file.enums) e.file.clear(), e.line = e.column = 0;
  for (auto& t : file.typedefs) t.file.clear(), t.line = t.column = 0;
  for (auto& c : file.constants) c.file.clear(), c.comment.clear(), c.line = c.column = 0;
  // The text written back declares in an order of its own.
  const auto by_name = [](const auto& a, const auto& b) { return a.name < b.name; };
  std::sort(file.structs.begin(), file.structs.end(), by_name);
  std::sort(file.typedefs.begin(), file.typedefs.end(), by_name);
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const std::size_t end = input.find('\0', start);
    parts.push_back(input.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  std::map<std::string, std::string_view> served;  // include name -> its text
  const cosmic::IdlIncludeLoader load = [&](std::string_view name) -> std::optional<std::string> {
    const std::size_t index = served.size() + 1;
    if (index >= parts.size()) return std::nullopt;
    return std::string(served.emplace(std::string(name), parts[index]).first->second);
  };
  const cosmic::IdlTypeFile file = cosmic::parse_idl_types(parts[0], load);
  const auto located = [&](const cosmic::IdlError& e) {
    const auto hit = served.find(e.file);
    const std::string_view text = e.file.empty() ? parts[0] : hit == served.end() ? std::string_view() : hit->second;
    require(!e.message.empty() && (e.file.empty() || hit != served.end()));
    require(e.line == 0 || (e.line <= idl_line_count(text) && e.column >= 1));
  };
  for (const auto& e : file.errors) located(e);
  require(file.errors.size() <= 101);
  if (!file.ok()) return 0;
  require(file.structs.size() + file.enums.size() + file.typedefs.size() + file.constants.size() <=
          cosmic::kIdlMaxDeclarations);
  for (const auto& s : file.structs) {
    require(s.members.size() <= cosmic::kIdlMaxMembers);
    for (const auto& m : s.members) require(m.dimensions.size() <= cosmic::kIdlMaxDimensions);
    const cosmic::IdlChannelType typed = cosmic::idl_channel_type(file, s);
    if (typed.ok()) require(cosmic::check_type(typed.type).empty());
    for (const auto& e : typed.errors) located(e);
  }
  const std::string again_text = to_idl(file);
  if (again_text.size() > cosmic::kIdlMaxTextBytes) return 0;  // the includes' texts together
  const cosmic::IdlTypeFile again = cosmic::parse_idl_types(again_text);
  require(again.ok());
  require(types_only(again) == types_only(file));
  return 0;
}

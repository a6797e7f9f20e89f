#include "gen_names.hpp"

#include <array>
#include <cctype>
#include <cstdio>
#include <string_view>

namespace cosmicctl {
namespace {

// C++20's keywords and alternative tokens, and the macros of the standard headers the generated
// code includes that a field could be named like: declaring any of them as a member breaks.
constexpr std::array<std::string_view, 113> kUndeclarable{
    "alignas",     "alignof",   "and",        "and_eq",    "asm",       "auto",         "bitand",
    "bitor",       "bool",      "break",      "case",      "catch",     "char",         "char8_t",
    "char16_t",    "char32_t",  "class",      "compl",     "concept",   "const",        "consteval",
    "constexpr",   "constinit", "const_cast", "continue",  "co_await",  "co_return",    "co_yield",
    "decltype",    "default",   "delete",     "do",        "double",    "dynamic_cast", "else",
    "enum",        "explicit",  "export",     "extern",    "false",     "float",        "for",
    "friend",      "goto",      "if",         "inline",    "int",       "long",         "mutable",
    "namespace",   "new",       "noexcept",   "not",       "not_eq",    "nullptr",      "operator",
    "or",          "or_eq",     "private",    "protected", "public",    "register",     "reinterpret_cast",
    "requires",    "return",    "short",      "signed",    "sizeof",    "static",       "static_assert",
    "static_cast", "struct",    "switch",     "template",  "this",      "thread_local", "throw",
    "true",        "try",       "typedef",    "typeid",    "typename",  "union",        "unsigned",
    "using",       "virtual",   "void",       "volatile",  "wchar_t",   "while",        "xor",
    "xor_eq",      "std",       "compact",    "detail",    "NULL",      "EOF",          "errno",
    "assert",      "offsetof",  "stdin",      "stdout",    "stderr",    "SIZE_MAX",     "INT8_MIN",
    "INT8_MAX",    "INT16_MIN", "INT16_MAX",  "INT32_MIN", "INT32_MAX", "INT64_MIN",    "INT64_MAX",
    "UINT8_MAX",
};

bool undeclarable(const std::string& name) {
  for (const std::string_view word : kUndeclarable) {
    if (word == name) return true;
  }
  return false;
}

}  // namespace

std::string identifier(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "c_" + out;
  return out;
}

std::string camel(const std::string& name) {
  std::string out;
  bool up = true;
  for (char c : identifier(name)) {
    if (c == '_') {
      up = true;
      continue;
    }
    out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return out.empty() ? "Component" : out;
}

std::string comment_text(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '\\') c = '?';
  }
  return out;
}

std::string literal_text(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (byte < 0x20 || byte >= 0x7f) {
      // Octal, not hex: a hex escape would swallow the hex digits after it.
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\%03o", static_cast<unsigned>(byte));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out;
}

std::string fill(std::string text, const std::map<std::string, std::string>& values) {
  for (const auto& [key, value] : values) {
    const std::string mark = "{{" + key + "}}";
    for (auto at = text.find(mark); at != std::string::npos; at = text.find(mark, at + value.size()))
      text.replace(at, mark.size(), value);
  }
  return text;
}

std::string declarable(const std::string& name) {
  std::string out = name;
  while (undeclarable(out)) out += '_';
  return out;
}

std::string NameScope::take(const std::string& wanted, const std::set<std::string>& others) {
  std::string name = declarable(wanted);
  while (taken_.count(name) || others.count(name)) name = declarable(name + "_");
  taken_.insert(name);
  return name;
}

}  // namespace cosmicctl

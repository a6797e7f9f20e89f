// Names and text for `cosmicctl gen` (gen_skeleton.cpp, gen_struct.cpp): model names made C++
// identifiers, text made safe for where it lands in generated code, and the names one C++ scope
// hands out without two clashing.
#pragma once

#include <map>
#include <set>
#include <string>
#include <utility>

namespace cosmicctl {

// A C++ identifier from a model name ([A-Za-z0-9_.-]).
std::string identifier(const std::string& name);
// The identifier in CamelCase ("actual_speed" -> "ActualSpeed").
std::string camel(const std::string& name);
// Text for a `//` or `#` comment: control characters (a newline would end the comment and let the
// rest become code) and backslashes (one at the end would splice the next line into the comment)
// shown as '?'.
std::string comment_text(const std::string& text);
// The body of a C++ string literal: '\\' and '"' escaped, anything not printable ASCII as a
// three-digit octal escape.
std::string literal_text(const std::string& text);
// Every {{KEY}} of `text` replaced by its value.
std::string fill(std::string text, const std::map<std::string, std::string>& values);

// The names declared in one C++ scope (a struct's members, nested types and constants). A field
// may be named like a C++ keyword or a standard macro ("class", "errno") and two wanted names may
// meet ("Pose" for the type of both `pose` and `Pose`): take() appends '_' until the name is free.
class NameScope {
 public:
  // Names the scope must not declare (an enclosing struct's name, a nested struct's own members).
  explicit NameScope(std::set<std::string> reserved = {}) : taken_(std::move(reserved)) {}
  // `wanted`, or it with '_' appended until it is declarable, free here and none of `others`.
  std::string take(const std::string& wanted, const std::set<std::string>& others = {});

 private:
  std::set<std::string> taken_;
};

// `name` as it can be declared: a keyword or a standard library macro gets a '_' appended.
std::string declarable(const std::string& name);

}  // namespace cosmicctl

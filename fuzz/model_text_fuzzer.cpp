// cosmicctl gen / diagram input (issue 22, 'Also'): a model file, its path and the diagram's title
// are outside text that ends up inside generated C++ and Graphviz DOT. For every model the loader
// accepts:
//  - every generated C++ file lexes cleanly: string and character literals close on their line,
//    block comments close, so no model text can end a literal or a comment and become code;
//  - the DOT lexes cleanly: quoted strings close without a raw line break, HTML-like labels
//    balance and hold only known tags and well-formed entities, braces and brackets balance
//    (what `dot` 2.43 crashed on, issue 22 item 6, was markup in a label);
//  - the model file's path and the title change no file's structure: the output has as many
//    lines as with a plain path and title (a raw line break copied into a comment or a literal
//    would add one).
// Input: the model path (also the title; any bytes, line breaks included) up to the first NUL
// byte, then the YAML model.
#include <cstdint>
#include <string>
#include <string_view>

#include "cosmic/config_loader.hpp"
#include "diagram_dot.hpp"
#include "fuzz_input.hpp"
#include "gen_skeleton.hpp"

using cosmic::fuzz::require;

namespace {

// C++ as the generator writes it: no raw strings, no digit separators.
void require_clean_cpp(std::string_view text) {
  enum class In { code, line_comment, block_comment, string, character } in = In::code;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    switch (in) {
      case In::code:
        if (c == '/' && next == '/')
          in = In::line_comment, ++i;
        else if (c == '/' && next == '*')
          in = In::block_comment, ++i;
        else if (c == '"')
          in = In::string;
        else if (c == '\'')
          in = In::character;
        break;
      case In::line_comment:
        require(c != '\\' || next != '\n');  // a backslash would continue the comment
        if (c == '\n') in = In::code;
        break;
      case In::block_comment:
        if (c == '*' && next == '/') in = In::code, ++i;
        break;
      case In::string:
      case In::character:
        require(c != '\n');
        if (c == '\\') {
          require(next != '\n' && next != '\0');
          ++i;
        } else if ((c == '"' && in == In::string) || (c == '\'' && in == In::character)) {
          in = In::code;
        }
        break;
    }
  }
  require(in == In::code || in == In::line_comment);
}

bool known_html_tag(std::string_view tag) {
  if (!tag.empty() && tag.front() == '/') tag.remove_prefix(1);
  const std::size_t end = tag.find_first_of(" /");
  const std::string_view name = tag.substr(0, end);
  for (const char* known : {"TABLE", "TR", "TD", "FONT", "B", "I", "BR", "U", "SUB", "SUP", "HR", "VR"}) {
    if (name == known) return true;
  }
  return false;
}

// An HTML-like label's body from `i` (just after its opening '<'); returns the index after the
// closing '>'.
std::size_t require_clean_html(std::string_view dot, std::size_t i) {
  int depth = 1;
  while (depth > 0) {
    require(i < dot.size());
    const char c = dot[i];
    if (c == '<') {
      const std::size_t close = dot.find('>', i);
      require(close != std::string_view::npos);
      // Only the renderer's own tags: a '<' from the model would be markup (or end the label).
      require(known_html_tag(dot.substr(i + 1, close - i - 1)));
      i = close + 1;
      continue;
    }
    if (c == '>') {
      --depth;
      ++i;
      continue;
    }
    if (c == '&') {
      const std::size_t semicolon = dot.find(';', i);
      require(semicolon != std::string_view::npos && semicolon - i <= 8);
      const std::string_view entity = dot.substr(i + 1, semicolon - i - 1);
      require(entity == "amp" || entity == "lt" || entity == "gt" || entity == "quot" || entity == "apos" ||
              (entity.size() >= 2 && entity.front() == '#'));
      i = semicolon + 1;
      continue;
    }
    ++i;
  }
  return i;
}

void require_clean_dot(std::string_view dot) {
  int braces = 0;
  int brackets = 0;
  for (std::size_t i = 0; i < dot.size();) {
    const char c = dot[i];
    if (c == '"') {
      for (++i;; ++i) {
        require(i < dot.size() && dot[i] != '\n');
        if (dot[i] == '\\') {
          require(i + 1 < dot.size() && dot[i + 1] != '\n');
          ++i;
        } else if (dot[i] == '"') {
          break;
        }
      }
      ++i;
      continue;
    }
    if (c == '<') {
      i = require_clean_html(dot, i + 1);
      continue;
    }
    if (c == '{') ++braces;
    if (c == '}') require(--braces >= 0);
    if (c == '[') ++brackets;
    if (c == ']') require(--brackets >= 0);
    ++i;
  }
  require(braces == 0 && brackets == 0);
}

std::size_t lines(std::string_view text) {
  std::size_t n = 0;
  for (const char c : text) n += c == '\n';
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t end = input.find('\0');
  if (end == std::string_view::npos) return 0;
  const std::string path(input.substr(0, end));
  const cosmic::ConfigResult loaded = cosmic::parse_config(input.substr(end + 1), "model.yaml");
  if (!loaded.ok()) return 0;

  const cosmicctl::DiagramStatus no_status;
  for (const auto detail : {cosmicctl::DiagramDetail::compact, cosmicctl::DiagramDetail::tables}) {
    const std::string dot = cosmicctl::render_dot(loaded.config, no_status, path, detail);
    require_clean_dot(dot);
    require(lines(dot) == lines(cosmicctl::render_dot(loaded.config, no_status, "title", detail)));
  }

  for (const auto& component : loaded.config.components) {
    if (!cosmicctl::check_identifiers(loaded.config, component).ok()) continue;
    const auto skeleton = cosmicctl::generate_skeleton(loaded.config, component, path, "/usr/lib/cmake/cosmic_client");
    const auto plain =
        cosmicctl::generate_skeleton(loaded.config, component, "model.yaml", "/usr/lib/cmake/cosmic_client");
    for (const auto& [name, content] : skeleton.files) {
      const bool cpp = name.ends_with(".cpp") || name.ends_with(".hpp");
      if (cpp) require_clean_cpp(content);
      require(plain.files.count(name) == 1 && lines(plain.files.at(name)) == lines(content));
    }
  }
  return 0;
}

#include "folded_names.hpp"

namespace cosmic::config_detail {

bool FoldedNames::add(YamlReader& reader, const YAML::Node& name_node, const std::string& path, const std::string& kind,
                      const std::string& name) {
  std::string folded = name;
  for (char& c : folded) {
    if (c == '-' || c == '.') c = '_';
  }
  const auto [it, fresh] = folded_.emplace(folded, First{name, name_node.Mark().line + 1});
  if (fresh || it->second.name == name) return true;
  reader.error_at(
      name_node, path,
      kind + " name '" + name + "' and " + kind + " '" + it->second.name + "' (line " +
          std::to_string(it->second.line) + ") differ only in '-', '.' or '_'",
      "names that stay distinct as identifiers: they become " + folded + " in DDS topics, generated code and diagrams");
  return false;
}

}  // namespace cosmic::config_detail

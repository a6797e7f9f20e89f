#include "ros_type_loader.hpp"

#include <filesystem>

#include "cosmic/idl_types.hpp"
#include "cosmic/msg_types.hpp"
#include "cosmic/ros_type_files.hpp"
#include "type_file_loader.hpp"

namespace cosmic::config_detail {
namespace {

namespace fs = std::filesystem;

struct TypeMap {
  std::string file, name;
  std::vector<std::string> type_path;
  std::map<std::string, std::uint32_t> max_length;
};

// The keys an IDL or .msg type map shares; nullopt after reporting what is missing.
std::optional<TypeMap> read_type_map(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                     const char* format, const char* name_hint) {
  if (!reader.check_map(node, path, {format, "name", "max_length", "type_path"})) return std::nullopt;
  TypeMap map;
  const auto file = reader.string(node[format], key(path, format));
  if (!has(node, "name")) {
    reader.error_at(node, path, std::string("an ") + format + " type names its type", name_hint);
    return std::nullopt;
  }
  const auto name = reader.string(node["name"], key(path, "name"));
  if (has(node, "max_length")) map.max_length = parse_max_length(reader, node["max_length"], key(path, "max_length"));
  if (has(node, "type_path")) {
    // Resolved now, so a bind or state file written back names the same directories.
    if (auto dirs = reader.string_list(node["type_path"], key(path, "type_path"))) {
      for (const std::string& dir : *dirs)
        map.type_path.push_back((fs::path(reader.file()).parent_path() / dir).lexically_normal().string());
    }
  }
  if (!file || !name) return std::nullopt;
  map.file = *file;
  map.name = *name;
  return map;
}

}  // namespace

std::map<std::string, std::uint32_t> parse_max_length(YamlReader& reader, const YAML::Node& node,
                                                      const std::string& path) {
  std::map<std::string, std::uint32_t> out;
  if (!node.IsMap()) {
    reader.error_at(node, path, "max_length is a map of members to bounds", "max_length: {ranges: 1081}");
    return out;
  }
  for (const auto& entry : node) {
    const std::string member = entry.first.as<std::string>();
    if (const auto bound = reader.unsigned_int(entry.second, key(path, member), 1, kMaxTypeBound))
      out[member] = static_cast<std::uint32_t>(*bound);
  }
  return out;
}

std::optional<ChannelType> load_idl_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                         std::vector<std::string>& included) {
  const auto map = read_type_map(reader, node, path, "idl", "name: MODULE::NAME (a struct of the file)");
  if (!map) return std::nullopt;
  const auto loaded =
      load_named_file(reader, node["idl"], key(path, "idl"), map->file, included, kIdlMaxTextBytes, "IDL file");
  if (!loaded) return std::nullopt;
  const std::vector<std::string> roots = ros_type_roots(loaded->path, map->type_path);
  const IdlTypeFile idl = parse_idl_types(loaded->text, [&](std::string_view include) {
    return read_from_roots(roots, std::string(include), kIdlMaxTextBytes, included);
  });
  // An error in an included file is located there: its name as written, found on the roots.
  for (const IdlError& e : idl.errors) {
    const std::string where = e.file.empty() ? loaded->path : e.file;
    reader.error_in(ConfigError{where, e.line, e.column, key(path, "idl"), e.message, ""});
  }
  if (!idl.ok()) return std::nullopt;
  const IdlStruct* s = idl.find(map->name);
  if (s == nullptr) {
    std::string names;
    for (std::size_t i = 0; i < idl.structs.size() && i < 8; ++i) names += (i ? ", " : "") + idl.structs[i].name;
    reader.error_at(node["name"], key(path, "name"), "no struct '" + map->name + "' in " + loaded->path,
                    idl.structs.empty() ? "the file declares no struct" : "one of " + names);
    return std::nullopt;
  }
  IdlChannelType typed = idl_channel_type(idl, *s, map->max_length);
  for (const IdlError& e : typed.errors) {
    reader.error_in(
        ConfigError{e.file.empty() ? loaded->path : e.file, e.line, e.column, key(path, "name"), e.message, ""});
  }
  if (!typed.ok()) return std::nullopt;
  typed.type.source = TypeSource{TypeSource::Format::idl,
                                 loaded->path,
                                 s->name,
                                 map->max_length,
                                 {},
                                 {},
                                 map->type_path,
                                 typed.extensibility == CdrExtensibility::appendable};
  return std::move(typed.type);
}

std::optional<ChannelType> load_msg_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                         std::vector<std::string>& included) {
  const auto map = read_type_map(reader, node, path, "msg", "name: PACKAGE/msg/NAME");
  if (!map) return std::nullopt;
  const std::optional<MsgTypeName> name = msg_type_name(map->name);
  if (!name) {
    reader.error_at(node["name"], key(path, "name"), "'" + map->name + "' is not a ROS 2 message name",
                    "PACKAGE/msg/NAME, e.g. geometry_msgs/msg/Twist");
    return std::nullopt;
  }
  const auto loaded =
      load_named_file(reader, node["msg"], key(path, "msg"), map->file, included, kMsgMaxTextBytes, ".msg file");
  if (!loaded) return std::nullopt;
  const std::vector<std::string> roots = ros_type_roots(loaded->path, map->type_path);
  std::map<std::string, std::string> paths{{name->full(), loaded->path}};  // pkg/msg/Name -> file, for errors
  const MsgLoader load = [&](const std::string& package, const std::string& message) -> std::optional<std::string> {
    if (package == name->package && message == name->name) return loaded->text;
    const fs::path relative = fs::path(package) / "msg" / (message + ".msg");
    std::optional<std::string> text = read_from_roots(roots, relative.string(), kMsgMaxTextBytes, included);
    if (text) paths[package + "/msg/" + message] = included.back();
    return text;
  };
  MsgChannelType typed = msg_channel_type(name->package, name->name, load, map->max_length);
  for (const MsgTypeError& e : typed.errors) {
    const auto file = paths.find(e.file);
    reader.error_in(
        ConfigError{file != paths.end() ? file->second : e.file, e.line, e.column, key(path, "msg"), e.message, ""});
  }
  if (!typed.ok()) return std::nullopt;
  typed.type.source =
      TypeSource{TypeSource::Format::msg, loaded->path, name->full(), map->max_length, {}, {}, map->type_path, false};
  return std::move(typed.type);
}

}  // namespace cosmic::config_detail

namespace cosmic {

std::vector<std::string> ros_type_roots(const std::string& file, const std::vector<std::string>& type_path) {
  namespace fs = std::filesystem;
  std::vector<std::string> roots(type_path.begin(), type_path.end());
  const fs::path own = fs::path(file).parent_path();
  roots.push_back(own.string());
  if (own.filename() == "msg" && own.has_parent_path()) roots.push_back(own.parent_path().parent_path().string());
  return roots;
}

std::optional<std::string> read_from_roots(const std::vector<std::string>& roots, const std::string& relative,
                                           std::size_t max_bytes, std::vector<std::string>& read) {
  namespace fs = std::filesystem;
  for (const std::string& root : roots) {
    const std::string candidate = (fs::path(root) / relative).lexically_normal().string();
    std::string text;
    if (!config_detail::read_regular_file(candidate, text, max_bytes).empty()) continue;
    read.push_back(candidate);
    return text;
  }
  return std::nullopt;
}

}  // namespace cosmic

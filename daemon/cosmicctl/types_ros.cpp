// `cosmicctl types FILE.idl` and `FILE.msg` (types_ros.hpp).
#include "types_ros.hpp"

#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cosmic/idl_types.hpp"
#include "cosmic/msg_types.hpp"
#include "cosmic/ros_type_files.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

Json field_json(const cosmic::TypeField& f) {
  Json out{{"name", f.name}, {"type", cosmic::describe(f.type)}};
  if (!f.unit.empty()) out["unit"] = f.unit;
  if (f.minimum) out["min"] = *f.minimum;
  if (f.maximum) out["max"] = *f.maximum;
  return out;
}

Json fields_json(const cosmic::ChannelType& type) {
  Json fields = Json::array();
  for (const auto& f : type.fields) fields.push_back(field_json(f));
  return fields;
}

// An IDL constant's type as a channel type names it ("int32", "float64"), or "string".
std::string constant_type(const cosmic::IdlType& type) {
  if (type.kind == cosmic::IdlType::Kind::string) return "string";
  cosmic::FieldType scalar;
  scalar.scalar = type.scalar;
  return cosmic::describe(scalar);
}

std::string located(const std::string& file, int line, int column, const std::string& message) {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  return out + ": " + message;
}

void print_json(const std::string& file, const char* format, Json types, Json extra) {
  Json out{{"file", file}, {"format", format}, {"types", std::move(types)}};
  out.update(extra);
  std::cout << out.dump(2, ' ', false, Json::error_handler_t::replace) << "\n";
}

void print_type(const Json& t) {
  for (const Json& c : t["constants"]) {
    std::cout << "  const " << c["type"].get<std::string>() << " " << c["name"].get<std::string>() << " = "
              << c["value"].get<std::string>() << "\n";
  }
  for (const Json& f : t["fields"]) {
    std::cout << "  " << f["name"].get<std::string>() << ": " << f["type"].get<std::string>();
    if (f.contains("unit")) std::cout << " [" << f["unit"].get<std::string>() << "]";
    std::cout << "\n";
  }
  if (t.contains("error")) std::cout << "  not a type as it stands: " << t["error"].get<std::string>() << "\n";
}

}  // namespace

int run_idl_types(const RosTypesRequest& request, const GlobalOptions& global) {
  const std::vector<std::string> roots = cosmic::ros_type_roots(request.file, request.type_path);
  std::vector<std::string> read;
  const cosmic::IdlTypeFile idl = cosmic::parse_idl_types(request.text, [&](std::string_view include) {
    return cosmic::read_from_roots(roots, std::string(include), cosmic::kIdlMaxTextBytes, read);
  });
  if (!idl.ok()) {
    for (const auto& e : idl.errors)
      std::cerr << located(e.file.empty() ? request.file : e.file, e.line, e.column, e.message) << "\n";
    return kExitConfigError;
  }
  Json types = Json::array();
  for (const cosmic::IdlStruct& s : idl.structs) {
    const cosmic::IdlChannelType typed = cosmic::idl_channel_type(idl, s);
    Json entry{{"name", s.name},
               {"file", s.file.empty() ? request.file : s.file},
               {"line", s.line},
               {"extensibility", typed.extensibility == cosmic::CdrExtensibility::appendable ? "appendable" : "final"},
               {"constants", Json::array()},
               {"fields", fields_json(typed.type)}};
    const std::string prefix = s.name + "_Constants::";  // rosidl puts a message's constants there
    for (const auto& c : idl.constants) {
      if (c.name.starts_with(prefix)) {
        entry["constants"].push_back(
            {{"name", c.name.substr(prefix.size())}, {"type", constant_type(c.type)}, {"value", c.value}});
      }
    }
    if (!typed.ok()) {
      const auto& e = typed.errors.front();
      entry["error"] = located(e.file.empty() ? request.file : e.file, e.line, e.column, e.message);
    }
    types.push_back(std::move(entry));
  }
  if (global.json) {
    print_json(request.file, "idl", std::move(types), {{"read", read}});
    return kExitOk;
  }
  std::cout << request.file << ": IDL, " << idl.structs.size() << " structs"
            << (read.empty() ? std::string() : ", " + std::to_string(read.size()) + " included files") << "\n";
  for (const Json& t : types) {
    std::cout << t["name"].get<std::string>() << " (" << t["extensibility"].get<std::string>() << ")"
              << (t["file"] != request.file ? ", from " + t["file"].get<std::string>() : std::string()) << "\n";
    print_type(t);
  }
  return kExitOk;
}

int run_msg_types(const RosTypesRequest& request, const GlobalOptions& global) {
  namespace fs = std::filesystem;
  // pkg/msg/Name from --name, or from FILE's own place (ROOT/pkg/msg/Name.msg).
  const fs::path path(request.file);
  const std::string guessed = path.parent_path().parent_path().filename().string() + "/msg/" + path.stem().string();
  const std::optional<cosmic::MsgTypeName> name = cosmic::msg_type_name(request.name.empty() ? guessed : request.name);
  if (!name || (request.name.empty() && path.parent_path().filename() != "msg")) {
    std::cerr << "cosmicctl types: " << request.file << ": "
              << (request.name.empty()
                      ? "a .msg file's package comes from its place, ROOT/PKG/msg/NAME.msg; give --name "
                        "PKG/msg/NAME"
                      : "'" + request.name + "' is not a ROS 2 message name (PKG/msg/NAME)")
              << "\n";
    return kExitUsage;
  }
  const std::vector<std::string> roots = cosmic::ros_type_roots(request.file, request.type_path);
  std::vector<std::string> read;
  std::map<std::string, std::string> paths{{name->full(), request.file}};  // pkg/msg/Name -> file, for errors
  const cosmic::MsgLoader load = [&](const std::string& package, const std::string& message) {
    if (package == name->package && message == name->name) return std::optional<std::string>(request.text);
    auto text = cosmic::read_from_roots(roots, (fs::path(package) / "msg" / (message + ".msg")).string(),
                                        cosmic::kMsgMaxTextBytes, read);
    if (text) paths[package + "/msg/" + message] = read.back();
    return text;
  };
  const cosmic::MsgChannelType typed = cosmic::msg_channel_type(name->package, name->name, load);
  if (!typed.ok()) {
    for (const auto& e : typed.errors) {
      const auto file = paths.find(e.file);
      std::cerr << located(file != paths.end() ? file->second : e.file, e.line, e.column, e.message) << "\n";
    }
    return kExitConfigError;
  }
  const cosmic::MsgFile own = cosmic::parse_msg(request.text);
  Json entry{{"name", name->full()}, {"constants", Json::array()}, {"fields", fields_json(typed.type)}};
  for (const auto& c : own.constants)
    entry["constants"].push_back({{"name", c.name}, {"type", c.type}, {"value", c.value}});
  Json files = Json::array();
  for (const auto& f : typed.files) files.push_back({{"name", f.name}, {"built_in", f.built_in}});
  if (global.json) {
    print_json(request.file, "msg", Json::array({entry}), {{"messages", files}, {"read", read}});
    return kExitOk;
  }
  std::cout << request.file << ": ROS 2 message " << name->full() << ", " << typed.files.size() << " messages read\n";
  print_type(entry);
  return kExitOk;
}

}  // namespace cosmicctl

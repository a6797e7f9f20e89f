// cosmic-msg-types-peer: the gateway's reading of ROS 2 .msg files (cosmic/msg_types.hpp) as JSON,
// so that a test can hold it against rosidl's own reader (tests/integration/msg_types/rosidl_test.py):
//   cosmic-msg-types-peer parse < FILE.msg
//     -> {"fields": [...], "constants": [...], "errors": ["LINE:COLUMN: message", ...]}
//   cosmic-msg-types-peer type TYPE_PATH_DIR pkg/msg/Name [PATH=MAX_LENGTH...]
//     -> {"files": [{"name", "built_in", "text", "fields", "constants"}, ...], "type": [fields],
//         "errors": ["pkg/msg/Name:LINE:COLUMN: message", ...]}
// where a .msg field is {"name", "package", "type", "string_bound", "array", "array_size",
// "default" (null: none), "unit"}, a constant {"type", "name", "value"}, and a channel type's field
// {"name", "unit", "type": {"kind", "scalar" | "bound" and "element" | "fields"}}. Messages are read
// from TYPE_PATH_DIR/pkg/msg/Name.msg. Exit status 2 on a wrong command line.
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cosmic/msg_types.hpp"

namespace {

using Json = nlohmann::json;

std::string array_name(cosmic::MsgFieldType::Array a) {
  switch (a) {
    case cosmic::MsgFieldType::Array::none:
      return "none";
    case cosmic::MsgFieldType::Array::fixed:
      return "fixed";
    case cosmic::MsgFieldType::Array::bounded:
      return "bounded";
    case cosmic::MsgFieldType::Array::unbounded:
      return "unbounded";
  }
  return "?";
}

Json file_json(const cosmic::MsgFile& file) {
  Json out{{"fields", Json::array()}, {"constants", Json::array()}, {"errors", Json::array()}};
  for (const auto& f : file.fields) {
    out["fields"].push_back({{"name", f.name},
                             {"package", f.type.package},
                             {"type", f.type.name},
                             {"string_bound", f.type.string_bound},
                             {"array", array_name(f.type.array)},
                             {"array_size", f.type.array_size},
                             {"default", f.default_value ? Json(*f.default_value) : Json()},
                             {"unit", f.unit}});
  }
  for (const auto& c : file.constants)
    out["constants"].push_back({{"type", c.type}, {"name", c.name}, {"value", c.value}});
  for (const auto& e : file.errors)
    out["errors"].push_back(std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  return out;
}

Json type_json(const cosmic::FieldType& t);

Json fields_json(const std::vector<cosmic::TypeField>& fields) {
  Json out = Json::array();
  for (const auto& f : fields) out.push_back({{"name", f.name}, {"unit", f.unit}, {"type", type_json(f.type)}});
  return out;
}

Json type_json(const cosmic::FieldType& t) {
  using Kind = cosmic::FieldType::Kind;
  switch (t.kind) {
    case Kind::scalar:
    case Kind::enumeration:
      return {{"kind", "scalar"}, {"scalar", std::string(cosmic::scalar_name(t.scalar))}};
    case Kind::string:
      return {{"kind", "string"}, {"bound", t.bound}};
    case Kind::array:
    case Kind::sequence:
      return {{"kind", t.kind == Kind::array ? "array" : "sequence"},
              {"bound", t.bound},
              {"element", t.element.empty() ? Json() : type_json(t.element.front())}};
    case Kind::record:
      return {{"kind", "record"}, {"fields", fields_json(t.fields)}};
  }
  return {};
}

std::optional<std::string> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

int type_command(int argc, char** argv) {
  const std::string dir = argv[2];
  const auto name = cosmic::msg_type_name(argv[3]);
  if (!name) {
    std::cerr << "not a message name: " << argv[3] << "\n";
    return 2;
  }
  std::map<std::string, std::uint32_t> max_length;
  for (int i = 4; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto equals = arg.rfind('=');
    if (equals == std::string::npos) return 2;
    max_length[arg.substr(0, equals)] = static_cast<std::uint32_t>(std::stoul(arg.substr(equals + 1)));
  }
  std::map<std::string, std::string> texts;  // what the loader read, by full name
  const cosmic::MsgLoader load = [&](const std::string& package, const std::string& message) {
    auto text = read_file(dir + "/" + package + "/msg/" + message + ".msg");
    if (text) texts[package + "/msg/" + message] = *text;
    return text;
  };
  const cosmic::MsgChannelType typed = cosmic::msg_channel_type(name->package, name->name, load, max_length);
  Json out{{"files", Json::array()}, {"type", fields_json(typed.type.fields)}, {"errors", Json::array()}};
  for (const auto& source : typed.files) {
    const auto parsed = cosmic::msg_type_name(source.name);
    const std::string text =
        source.built_in ? std::string(*cosmic::msg_builtin_text(parsed->package, parsed->name)) : texts[source.name];
    Json file = file_json(cosmic::parse_msg(text));
    file["name"] = source.name;
    file["built_in"] = source.built_in;
    file["text"] = text;
    out["files"].push_back(file);
  }
  for (const auto& e : typed.errors) {
    out["errors"].push_back(e.file + ":" + std::to_string(e.line) + ":" + std::to_string(e.column) + ": " + e.message);
  }
  std::cout << out.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "parse" && argc == 2) {
    std::ostringstream text;
    text << std::cin.rdbuf();
    std::cout << file_json(cosmic::parse_msg(text.str())).dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
    return 0;
  }
  if (command == "type" && argc >= 4) return type_command(argc, argv);
  std::cerr << "usage: cosmic-msg-types-peer parse < FILE.msg | type TYPE_PATH_DIR pkg/msg/Name [PATH=N...]\n";
  return 2;
}

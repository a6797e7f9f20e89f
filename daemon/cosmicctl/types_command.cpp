// `cosmicctl types FILE`: what a type file defines, as a typed channel would see it (issue 35). A
// DBC file (.dbc): every message with its identifier, length and cycle time, and the fields its
// signals become (cosmic/dbc_type.hpp) with each signal's layout, or why the message cannot be a
// channel's type. An LCM type file (.lcm): every struct with the fingerprint lcm-gen gives it, its
// constants and its fields (cosmic/lcm_types.hpp). An IDL file or a ROS 2 message: types_ros.hpp.
// With --json the same as one JSON document.
// Offline: reads FILE, nothing else.
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "cosmic/dbc.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/lcm_types.hpp"
#include "types_ros.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

struct TypesOptions {
  std::string file;
  std::vector<std::string> type_path;  // IDL includes and .msg dependencies
  std::string name;                    // .msg: pkg/msg/Name when FILE's place does not say
};

// The whole of FILE when it is a regular file of at most kDbcMaxTextBytes; else prints why.
std::optional<std::string> read_type_file(const std::string& file) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) {
    std::cerr << "cosmicctl types: cannot read " << file << ": " << std::strerror(errno) << "\n";
    return std::nullopt;
  }
  if (!S_ISREG(info.st_mode) || static_cast<std::uint64_t>(info.st_size) > cosmic::kDbcMaxTextBytes) {
    std::cerr << "cosmicctl types: " << file << " is not a regular file of at most " << (cosmic::kDbcMaxTextBytes >> 20)
              << " MiB\n";
    return std::nullopt;
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) {
    std::cerr << "cosmicctl types: cannot read " << file << "\n";
    return std::nullopt;
  }
  return text.str();
}

std::string hex_id(const cosmic::DbcMessage& m) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, m.extended ? "0x%08X" : "0x%03X", m.can_id);
  return buffer;
}

// "8|16@1+ (0.01,0)", as SG_ writes it.
std::string layout(const cosmic::DbcSignal& s) {
  std::ostringstream out;
  out << s.start_bit << "|" << s.size << "@" << (s.order == cosmic::DbcByteOrder::big_endian ? "0" : "1")
      << (s.is_signed ? "-" : "+") << " (" << cosmic::shortest_number_text(s.factor) << ","
      << cosmic::shortest_number_text(s.offset) << ")";
  if (s.value_type != cosmic::DbcValueType::integer)
    out << (s.value_type == cosmic::DbcValueType::float32 ? " float32" : " float64");
  return out.str();
}

// The signal a field of the message's type comes from (the same name; the switch's field is first).
const cosmic::DbcSignal& signal_of(const cosmic::DbcMessage& m, const cosmic::TypeField& f) {
  return *std::find_if(m.signals.begin(), m.signals.end(),
                       [&](const cosmic::DbcSignal& s) { return s.name == f.name; });
}

Json field_json(const cosmic::TypeField& f, const cosmic::DbcSignal& s) {
  Json out{{"name", f.name}, {"type", cosmic::describe(f.type)}, {"layout", layout(s)}};
  if (!f.unit.empty()) out["unit"] = f.unit;
  if (f.minimum) out["min"] = *f.minimum;
  if (f.maximum) out["max"] = *f.maximum;
  if (f.present_when) out["present_when"] = {{"selector", f.present_when->selector}, {"value", f.present_when->value}};
  return out;
}

Json message_json(const cosmic::DbcMessage& m) {
  Json out{{"name", m.name},     {"can_id", m.can_id}, {"extended", m.extended},
           {"length", m.length}, {"line", m.line},     {"cycle_ms", nullptr}};
  if (m.cycle_time) out["cycle_ms"] = std::chrono::duration<double, std::milli>(*m.cycle_time).count();
  const cosmic::DbcChannelType typed = cosmic::channel_type_from_dbc(m);
  if (!typed.ok()) {
    out["error"] = std::to_string(typed.errors.front().line) + ":" + std::to_string(typed.errors.front().column) +
                   ": " + typed.errors.front().message;
    return out;
  }
  Json fields = Json::array();
  for (std::size_t i = 0; i < typed.type.fields.size(); ++i)
    fields.push_back(field_json(typed.type.fields[i], signal_of(m, typed.type.fields[i])));
  out["fields"] = std::move(fields);
  return out;
}

void print_message(const cosmic::DbcMessage& m) {
  std::cout << m.name << ": id " << hex_id(m) << (m.extended ? " (extended)" : "") << ", " << m.length << " bytes, ";
  if (m.cycle_time) {
    std::cout << "every "
              << cosmic::shortest_number_text(std::chrono::duration<double, std::milli>(*m.cycle_time).count())
              << " ms\n";
  } else {
    std::cout << "on event\n";
  }
  const cosmic::DbcChannelType typed = cosmic::channel_type_from_dbc(m);
  if (!typed.ok()) {
    for (const auto& e : typed.errors) std::cout << "  not a type: line " << e.line << ": " << e.message << "\n";
    return;
  }
  // One field per signal, in order: the type beside the layout it comes from.
  for (std::size_t i = 0; i < typed.type.fields.size(); ++i) {
    std::cout << "  " << cosmic::describe(typed.type.fields[i]) << "   <- "
              << layout(signal_of(m, typed.type.fields[i])) << "\n";
  }
}

std::string hex64(std::uint64_t v) {
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "0x%016llx", static_cast<unsigned long long>(v));
  return buffer;
}

int run_lcm_types(const TypesOptions& o, const GlobalOptions& global, const std::string& text) {
  const cosmic::LcmTypeFile file = cosmic::parse_lcm_types(text);
  if (!file.ok()) {
    for (const auto& e : file.errors)
      std::cerr << o.file << ":" << e.line << ":" << e.column << ": " << e.message << "\n";
    return kExitConfigError;
  }
  Json types = Json::array();
  for (const cosmic::LcmStruct& s : file.structs) {
    const auto fingerprint = cosmic::lcm_fingerprint(file, s);
    const cosmic::LcmChannelType typed = cosmic::lcm_channel_type(file, s);
    Json entry{
        {"name", s.full_name()}, {"line", s.line}, {"fingerprint", fingerprint ? Json(hex64(*fingerprint)) : Json()}};
    Json constants = Json::array();
    for (const auto& c : s.constants) constants.push_back({{"name", c.name}, {"type", c.type}, {"value", c.value}});
    entry["constants"] = std::move(constants);
    Json fields = Json::array();
    for (const auto& f : typed.type.fields) fields.push_back({{"name", f.name}, {"type", cosmic::describe(f.type)}});
    entry["fields"] = std::move(fields);
    if (!typed.ok()) {
      entry["error"] = std::to_string(typed.errors.front().line) + ":" + std::to_string(typed.errors.front().column) +
                       ": " + typed.errors.front().message;
    }
    types.push_back(std::move(entry));
  }
  if (global.json) {
    std::cout << Json{{"file", o.file}, {"format", "lcm"}, {"types", std::move(types)}}.dump(
                     2, ' ', false, Json::error_handler_t::replace)
              << "\n";
    return kExitOk;
  }
  std::cout << o.file << ": LCM, " << file.structs.size() << " structs\n";
  for (const Json& t : types) {
    std::cout << t["name"].get<std::string>() << ": fingerprint "
              << (t["fingerprint"].is_null() ? std::string("none") : t["fingerprint"].get<std::string>()) << "\n";
    for (const Json& c : t["constants"]) {
      std::cout << "  const " << c["type"].get<std::string>() << " " << c["name"].get<std::string>() << " = "
                << c["value"].get<std::string>() << "\n";
    }
    for (const Json& f : t["fields"])
      std::cout << "  " << f["name"].get<std::string>() << ": " << f["type"].get<std::string>() << "\n";
    if (t.contains("error")) std::cout << "  not a type as it stands: line " << t["error"].get<std::string>() << "\n";
  }
  return kExitOk;
}

int run_types(const TypesOptions& o, const GlobalOptions& global) {
  const bool lcm = o.file.ends_with(".lcm");
  const bool idl = o.file.ends_with(".idl");
  const bool msg = o.file.ends_with(".msg");
  if (!lcm && !idl && !msg && !o.file.ends_with(".dbc") && !o.file.ends_with(".DBC")) {
    std::cerr << "cosmicctl types: " << o.file << ": not a DBC file (.dbc), an LCM type file (.lcm), an IDL file "
              << "(.idl) or a ROS 2 message (.msg), the type files this version reads\n";
    return kExitUsage;
  }
  if (!msg && !o.name.empty()) {
    std::cerr << "cosmicctl types: --name names a .msg file's message; " << o.file << " says its own names\n";
    return kExitUsage;
  }
  const auto text = read_type_file(o.file);
  if (!text) return kExitConfigError;
  if (lcm) return run_lcm_types(o, global, *text);
  if (idl || msg) {
    const RosTypesRequest request{o.file, *text, o.type_path, o.name};
    return idl ? run_idl_types(request, global) : run_msg_types(request, global);
  }
  const cosmic::DbcFile dbc = cosmic::parse_dbc(*text);
  if (!dbc.ok()) {
    for (const auto& e : dbc.errors)
      std::cerr << o.file << ":" << e.line << ":" << e.column << ": " << e.message << "\n";
    return kExitConfigError;
  }
  if (global.json) {
    Json types = Json::array();
    for (const auto& m : dbc.messages) types.push_back(message_json(m));
    // A DBC file's units and names may be Windows-1252, not UTF-8: replaced, never a throw.
    std::cout << Json{{"file", o.file}, {"format", "dbc"}, {"types", std::move(types)}}.dump(
                     2, ' ', false, Json::error_handler_t::replace)
              << "\n";
    return kExitOk;
  }
  std::cout << o.file << ": DBC, " << dbc.messages.size() << " messages\n";
  for (const auto& m : dbc.messages) print_message(m);
  return kExitOk;
}

}  // namespace

CommandRunner add_types_command(CLI::App& app, const GlobalOptions& options) {
  auto* command = app.add_subcommand(
      "types",
      "List the types a DBC, LCM, IDL or ROS 2 .msg file defines, as a typed channel (type: {dbc|lcm|idl|msg: ...}) "
      "sees them");
  auto o = std::make_shared<TypesOptions>();
  command
      ->add_option(
          "FILE", o->file,
          "Type file: a DBC file (.dbc), an LCM type file (.lcm), an IDL file (.idl) or a ROS 2 message (.msg)")
      ->required();
  command->add_option("--type-path", o->type_path,
                      "Where included IDL files and referenced messages are found (DIR/pkg/msg/Name.*; repeatable)");
  command->add_option("--name", o->name, "A .msg file's message, PKG/msg/NAME, when its place does not say");
  return [command, o, &options]() -> int {
    if (!command->parsed()) return -1;
    return run_types(*o, options);
  };
}

}  // namespace cosmicctl

#include "type_loader.hpp"

#include <algorithm>
#include <array>
#include <map>

#include "cosmic/dbc_type.hpp"
#include "cosmic/lcm_types.hpp"
#include "ros_type_loader.hpp"
#include "type_file_loader.hpp"

namespace cosmic::config_detail {
namespace {

constexpr const char* kTypeWords =
    "bool, int8, int16, int32, int64, uint8, uint16, uint32, uint64, float32, float64, enum, string, array, sequence, "
    "record";

// The keys a field's (or an element's) type may have, beside `type`, by kind.
const char* keys_of(FieldType::Kind kind) {
  switch (kind) {
    case FieldType::Kind::scalar:
      return "";
    case FieldType::Kind::enumeration:
      return "values, underlying";
    case FieldType::Kind::string:
      return "max_length";
    case FieldType::Kind::array:
      return "length, element";
    case FieldType::Kind::sequence:
      return "max_length, element";
    case FieldType::Kind::record:
      return "fields";
  }
  return "";
}

class TypeLoader {
 public:
  TypeLoader(YamlReader& reader, std::vector<std::string>& included) : reader_(reader), included_(included) {}

  std::optional<ChannelType> parse(const YAML::Node& node, const std::string& path) {
    if (node.IsMap() && has(node, "dbc")) return from_dbc(node, path);
    if (node.IsMap() && has(node, "lcm")) return from_lcm(node, path);
    if (node.IsMap() && has(node, "idl")) return load_idl_type(reader_, node, path, included_);
    if (node.IsMap() && has(node, "msg")) return load_msg_type(reader_, node, path, included_);
    if (!reader_.check_map(node, path, {"fields"})) return std::nullopt;
    const std::size_t errors_before = reader_.error_count();
    ChannelType type;
    if (!has(node, "fields")) {
      reader_.error_at(node, path, "a type needs its fields", "fields: [{name: NAME, type: float64}, ...]");
      return std::nullopt;
    }
    type.fields = fields(node["fields"], key(path, "fields"), "", 0);
    if (reader_.error_count() != errors_before) return std::nullopt;
    // What only the whole type shows (names twice, ranges against kinds, sizes), at its place.
    for (const TypeProblem& p : check_type(type)) {
      const auto at = places_.find(p.where);
      const auto& [place, place_path] = at != places_.end() ? at->second : std::pair{node, path};
      reader_.error_at(place, place_path, p.what);
    }
    if (reader_.error_count() != errors_before) return std::nullopt;
    return type;
  }

 private:
  // {dbc: FILE, message: NAME}: the message's signals as fields (cosmic/dbc_type.hpp).
  std::optional<ChannelType> from_dbc(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"dbc", "message", "e2e"})) return std::nullopt;
    const auto file = reader_.string(node["dbc"], key(path, "dbc"));
    if (!has(node, "message")) {
      reader_.error_at(node, path, "a DBC type names its message", "message: NAME (a BO_ of the DBC file)");
      return std::nullopt;
    }
    const auto name = reader_.string(node["message"], key(path, "message"));
    if (!file || !name) return std::nullopt;
    const auto loaded = load_dbc_file(reader_, node["dbc"], key(path, "dbc"), *file, included_);
    if (!loaded) return std::nullopt;
    const auto& messages = loaded->file.messages;
    const auto message =
        std::find_if(messages.begin(), messages.end(), [&](const DbcMessage& m) { return m.name == *name; });
    if (message == messages.end()) {
      reader_.error_at(node["message"], key(path, "message"),
                       "no message " + quote_value(*name) + " in " + loaded->path, message_names(messages));
      return std::nullopt;
    }
    std::optional<E2eSpec> e2e;
    if (has(node, "e2e")) {
      e2e = parse_e2e(reader_, node["e2e"], key(path, "e2e"), *message);
      if (!e2e) return std::nullopt;
    }
    DbcChannelType typed = channel_type_from_dbc(e2e ? e2e_payload_message(*message, *e2e) : *message);
    for (const DbcError& e : typed.errors)
      reader_.error_in(ConfigError{loaded->path, e.line, e.column, key(path, "message"), e.message, ""});
    if (!typed.ok()) return std::nullopt;
    typed.type.source = TypeSource{TypeSource::Format::dbc, loaded->path, message->name, {}, *message, {}};
    typed.type.source->e2e = e2e;
    return std::move(typed.type);
  }

  // {lcm: FILE, name: pkg.type_t, max_length: {MEMBER: N}}: the struct's members as fields
  // (cosmic/lcm_types.hpp).
  std::optional<ChannelType> from_lcm(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"lcm", "name", "max_length"})) return std::nullopt;
    const auto file = reader_.string(node["lcm"], key(path, "lcm"));
    if (!has(node, "name")) {
      reader_.error_at(node, path, "an LCM type names its struct", "name: PACKAGE.TYPE (a struct of the file)");
      return std::nullopt;
    }
    const auto name = reader_.string(node["name"], key(path, "name"));
    std::map<std::string, std::uint32_t> max_length;
    if (has(node, "max_length")) max_length = parse_max_length(reader_, node["max_length"], key(path, "max_length"));
    if (!file || !name) return std::nullopt;
    const auto loaded =
        load_named_file(reader_, node["lcm"], key(path, "lcm"), *file, included_, kLcmMaxTextBytes, "LCM type file");
    if (!loaded) return std::nullopt;
    const LcmTypeFile lcm = parse_lcm_types(loaded->text);
    for (const LcmError& e : lcm.errors)
      reader_.error_in(ConfigError{loaded->path, e.line, e.column, key(path, "lcm"), e.message, ""});
    if (!lcm.ok()) return std::nullopt;
    const LcmStruct* s = lcm.find(*name);
    if (s == nullptr) {
      std::string names;
      for (std::size_t i = 0; i < lcm.structs.size() && i < 8; ++i)
        names += (i ? ", " : "") + lcm.structs[i].full_name();
      reader_.error_at(node["name"], key(path, "name"), "no struct " + quote_value(*name) + " in " + loaded->path,
                       lcm.structs.empty() ? "the file declares no struct" : "one of " + names);
      return std::nullopt;
    }
    LcmChannelType typed = lcm_channel_type(lcm, *s, max_length);
    for (const LcmError& e : typed.errors)
      reader_.error_in(ConfigError{loaded->path, e.line, e.column, key(path, "name"), e.message, ""});
    if (!typed.ok()) return std::nullopt;
    typed.type.source = TypeSource{TypeSource::Format::lcm,
                                   loaded->path,
                                   s->full_name(),
                                   max_length,
                                   {},
                                   std::make_shared<const LcmTypeFile>(lcm)};
    return std::move(typed.type);
  }

  // "one of A, B, C" (the first few) for an unknown message name.
  static std::string message_names(const std::vector<DbcMessage>& messages) {
    if (messages.empty()) return "the file declares no message";
    std::string out = "one of ";
    for (std::size_t i = 0; i < messages.size() && i < 8; ++i) out += (i ? ", " : "") + messages[i].name;
    return messages.size() > 8 ? out + ", ..." : out;
  }

  std::vector<TypeField> fields(const YAML::Node& list, const std::string& path, const std::string& where,
                                std::size_t depth) {
    std::vector<TypeField> out;
    if (!reader_.is_list(list, path)) return out;
    if (depth >= kMaxTypeDepth) {
      reader_.error_at(list, path, "nested more than " + std::to_string(kMaxTypeDepth) + " levels deep");
      return out;
    }
    if (list.size() > kMaxRecordFields) {
      reader_.error_at(list, path,
                       std::to_string(list.size()) + " fields, at most " + std::to_string(kMaxRecordFields));
      return out;
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (auto f = field(list[i], indexed(path, i), where, i, depth)) out.push_back(std::move(*f));
    }
    return out;
  }

  // Field `index` of the record at `where` (check_type()'s names for places: "pose.x", or
  // "pose.fields[1]" where a name does not tell the field apart).
  std::optional<TypeField> field(const YAML::Node& node, const std::string& path, const std::string& where,
                                 std::size_t index, std::size_t depth) {
    if (!reader_.check_map(node, path,
                           {"name", "type", "unit", "min", "max", "values", "underlying", "max_length", "length",
                            "element", "fields"})) {
      return std::nullopt;
    }
    TypeField f;
    if (!has(node, "name")) {
      reader_.error_at(node, path, "a field needs a name", "name: [A-Za-z][A-Za-z0-9_]*");
    } else if (auto name = reader_.string(node["name"], key(path, "name"))) {
      f.name = *name;
      if (!valid_field_name(f.name)) {
        reader_.error_at(node["name"], key(path, "name"), "field name '" + f.name + "' is not valid",
                         "[A-Za-z][A-Za-z0-9_]*, at most 64 characters");
      }
    }
    const std::string prefix = where.empty() ? "" : where + ".";
    const std::string here = prefix + f.name;
    places_.emplace(here, std::pair{node, path});
    places_.emplace(prefix + "fields[" + std::to_string(index) + "]", std::pair{node, path});
    if (auto type = field_type(node, path, here, depth)) f.type = std::move(*type);
    if (has(node, "unit")) f.unit = reader_.string(node["unit"], key(path, "unit")).value_or("");
    if (has(node, "min")) f.minimum = reader_.number(node["min"], key(path, "min"));
    if (has(node, "max")) f.maximum = reader_.number(node["max"], key(path, "max"));
    return f;
  }

  // The type of a field or an element: `node` holds `type` and the kind's keys.
  std::optional<FieldType> field_type(const YAML::Node& node, const std::string& path, const std::string& where,
                                      std::size_t depth) {
    if (!has(node, "type")) {
      reader_.error_at(node, path, "no type", std::string("type: one of ") + kTypeWords);
      return std::nullopt;
    }
    const auto word = reader_.string(node["type"], key(path, "type"));
    if (!word) return std::nullopt;
    FieldType t;
    if (const auto scalar = scalar_kind(*word)) {
      t.scalar = *scalar;
    } else if (*word == "enum") {
      t.kind = FieldType::Kind::enumeration;
    } else if (*word == "string") {
      t.kind = FieldType::Kind::string;
    } else if (*word == "array") {
      t.kind = FieldType::Kind::array;
    } else if (*word == "sequence") {
      t.kind = FieldType::Kind::sequence;
    } else if (*word == "record") {
      t.kind = FieldType::Kind::record;
    } else {
      reader_.error_at(node["type"], key(path, "type"), "unknown type '" + *word + "'",
                       std::string("one of ") + kTypeWords);
      return std::nullopt;
    }
    refuse_foreign_keys(node, path, t.kind);
    switch (t.kind) {
      case FieldType::Kind::scalar:
        break;
      case FieldType::Kind::enumeration:
        enumeration(node, path, t);
        break;
      case FieldType::Kind::string:
        t.bound = bound(node, path, "max_length");
        break;
      case FieldType::Kind::array:
      case FieldType::Kind::sequence:
        t.bound = bound(node, path, t.kind == FieldType::Kind::array ? "length" : "max_length");
        if (auto e = element(node, path, where, depth)) t.element.push_back(std::move(*e));
        break;
      case FieldType::Kind::record:
        if (!has(node, "fields")) {
          reader_.error_at(node, path, "a record needs its fields", "fields: [{name: NAME, type: float64}, ...]");
        } else {
          t.fields = fields(node["fields"], key(path, "fields"), where, depth + 1);
        }
        break;
    }
    return t;
  }

  void refuse_foreign_keys(const YAML::Node& node, const std::string& path, FieldType::Kind kind) {
    // Whole words: "length" is inside "max_length".
    const std::string allowed = std::string(", ") + keys_of(kind) + ",";
    for (const char* k : {"values", "underlying", "max_length", "length", "element", "fields"}) {
      if (!node[k] || allowed.find(std::string(", ") + k + ",") != std::string::npos) continue;
      reader_.error_at(node[k], key(path, k), std::string(k) + " does not belong to this type",
                       *keys_of(kind) ? std::string("for it: ") + keys_of(kind) : std::string("nothing more for it"));
    }
  }

  std::uint32_t bound(const YAML::Node& node, const std::string& path, const char* name) {
    if (!has(node, name)) {
      reader_.error_at(node, path, std::string("needs ") + name,
                       std::string(name) + ": 1.." + std::to_string(kMaxTypeBound));
      return 0;
    }
    return static_cast<std::uint32_t>(reader_.unsigned_int(node[name], key(path, name), 1, kMaxTypeBound).value_or(0));
  }

  void enumeration(const YAML::Node& node, const std::string& path, FieldType& t) {
    t.scalar = ScalarKind::int32;
    if (has(node, "underlying")) {
      const auto word = reader_.string(node["underlying"], key(path, "underlying"));
      const auto kind = word ? scalar_kind(*word) : std::nullopt;
      if (word && (!kind || !is_integer(*kind))) {
        reader_.error_at(node["underlying"], key(path, "underlying"), "'" + *word + "' is not an integer type",
                         "int8, int16, int32, int64, uint8, uint16, uint32 or uint64");
      } else if (kind) {
        t.scalar = *kind;
      }
    }
    const YAML::Node values = node["values"];
    if (!values || !values.IsMap() || values.size() == 0) {
      reader_.error_at(values ? values : node, key(path, "values"), "an enumeration needs its named values",
                       "values: {NAME: 0, OTHER: 1}");
      return;
    }
    for (const auto& entry : values) {
      const std::string name = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
      const std::string at = key(key(path, "values"), name);
      if (auto v = reader_.signed_int(entry.second, at)) t.values.push_back(EnumValue{name, *v});
    }
  }

  std::optional<FieldType> element(const YAML::Node& node, const std::string& path, const std::string& where,
                                   std::size_t depth) {
    if (!has(node, "element")) {
      reader_.error_at(node, path, "needs its element type", "element: float64, or element: {type: record, ...}");
      return std::nullopt;
    }
    const YAML::Node e = node["element"];
    const std::string at = key(path, "element");
    places_.emplace(where + ".element", std::pair{e, at});
    if (e.IsScalar()) {  // a scalar's name alone
      const auto kind = scalar_kind(e.Scalar());
      if (!kind) {
        reader_.error_at(e, at, "'" + e.Scalar() + "' is not a scalar type",
                         "a scalar's name, or a map: {type: record, fields: [...]}");
        return std::nullopt;
      }
      FieldType t;
      t.scalar = *kind;
      return t;
    }
    if (!reader_.check_map(e, at, {"type", "values", "underlying", "max_length", "length", "element", "fields"}))
      return std::nullopt;
    return field_type(e, at, where + ".element", depth + 1);
  }

  YamlReader& reader_;
  std::vector<std::string>& included_;                                // DBC files read
  std::map<std::string, std::pair<YAML::Node, std::string>> places_;  // check_type's "where" -> node, key path
};

void emit_fields(YAML::Node& list, const std::vector<TypeField>& fields);

YAML::Node type_to_yaml(const FieldType& t) {
  YAML::Node out;
  switch (t.kind) {
    case FieldType::Kind::scalar:
      out["type"] = std::string(scalar_name(t.scalar));
      break;
    case FieldType::Kind::enumeration:
      out["type"] = "enum";
      out["underlying"] = std::string(scalar_name(t.scalar));
      for (const EnumValue& v : t.values) out["values"][v.name] = v.value;
      break;
    case FieldType::Kind::string:
      out["type"] = "string";
      out["max_length"] = t.bound;
      break;
    case FieldType::Kind::array:
    case FieldType::Kind::sequence:
      out["type"] = t.kind == FieldType::Kind::array ? "array" : "sequence";
      out[t.kind == FieldType::Kind::array ? "length" : "max_length"] = t.bound;
      if (!t.element.empty()) out["element"] = type_to_yaml(t.element[0]);
      break;
    case FieldType::Kind::record: {
      YAML::Node list(YAML::NodeType::Sequence);
      emit_fields(list, t.fields);
      out["type"] = "record";
      out["fields"] = list;
      break;
    }
  }
  return out;
}

void emit_fields(YAML::Node& list, const std::vector<TypeField>& fields) {
  for (const TypeField& f : fields) {
    YAML::Node entry = type_to_yaml(f.type);
    entry["name"] = f.name;
    if (!f.unit.empty()) entry["unit"] = f.unit;
    // The shortest text that reads back as the same double.
    if (f.minimum) entry["min"] = shortest_number_text(*f.minimum);
    if (f.maximum) entry["max"] = shortest_number_text(*f.maximum);
    list.push_back(entry);
  }
}

}  // namespace

std::optional<ChannelType> parse_channel_type(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                              std::vector<std::string>& included) {
  return TypeLoader(reader, included).parse(node, path);
}

YAML::Node channel_type_to_yaml(const ChannelType& type) {
  if (type.source) {
    YAML::Node out;
    static constexpr const char* kFormatKey[] = {"dbc", "lcm", "idl", "msg"};
    const bool dbc = type.source->format == TypeSource::Format::dbc;
    out[kFormatKey[static_cast<std::size_t>(type.source->format)]] = type.source->file;
    out[dbc ? "message" : "name"] = type.source->name;
    if (const auto& e2e = type.source->e2e) {
      out["e2e"]["counter"] = e2e->counter;
      out["e2e"]["crc"] = e2e->crc;
      out["e2e"]["data_id"] = e2e->data_id;
      out["e2e"]["data_id_mode"] = to_string(e2e->data_id_mode);
    }
    for (const auto& [member, bound] : type.source->max_length) out["max_length"][member] = bound;
    for (const std::string& dir : type.source->type_path) out["type_path"].push_back(dir);
    return out;
  }
  YAML::Node list(YAML::NodeType::Sequence);
  emit_fields(list, type.fields);
  YAML::Node out;
  out["fields"] = list;
  return out;
}

}  // namespace cosmic::config_detail

// The JSON Schema of a channel type (cosmic/json_schema.hpp), mirroring what JsonWriter in
// json_representation.cpp writes for each kind of field.
#include "cosmic/json_schema.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

namespace cosmic {
namespace {

// ordered_json: "properties" must list the fields in their order, which std::map's json would sort.
using Schema = nlohmann::ordered_json;

// Most validators (ajv among them) read JSON numbers as doubles. A whole number below 2^53 in
// magnitude is a double no other whole number rounds to, so only such a number may be excluded or
// required by equality ("not": {"enum"}, "const"): a larger one could be equal, as doubles, to a
// different value the gateway writes, and the schema would refuse a sound event.
constexpr std::int64_t kExactInEveryReader = std::int64_t{1} << 53;

bool exact_in_every_reader(std::int64_t value) { return value > -kExactInEveryReader && value < kExactInEveryReader; }

template <typename Integer>
void limits_of(Schema& schema) {
  schema["minimum"] = std::numeric_limits<Integer>::lowest();
  schema["maximum"] = std::numeric_limits<Integer>::max();
}

// {"type": "integer"} with the kind's limits as exact whole numbers (scalar_limits' doubles round
// int64's and uint64's highest up, past what the kind holds).
Schema integer_schema(ScalarKind kind) {
  Schema schema{{"type", "integer"}};
  switch (kind) {
    case ScalarKind::int8:
      limits_of<std::int8_t>(schema);
      break;
    case ScalarKind::int16:
      limits_of<std::int16_t>(schema);
      break;
    case ScalarKind::int32:
      limits_of<std::int32_t>(schema);
      break;
    case ScalarKind::int64:
      limits_of<std::int64_t>(schema);
      break;
    case ScalarKind::uint8:
      limits_of<std::uint8_t>(schema);
      break;
    case ScalarKind::uint16:
      limits_of<std::uint16_t>(schema);
      break;
    case ScalarKind::uint32:
      limits_of<std::uint32_t>(schema);
      break;
    case ScalarKind::uint64:
      limits_of<std::uint64_t>(schema);
      break;
    case ScalarKind::boolean:
    case ScalarKind::float32:
    case ScalarKind::float64:
      break;
  }
  return schema;
}

Schema scalar_schema(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::boolean:
      return Schema{{"type", "boolean"}};
    case ScalarKind::float32:
      // Written as the double the float32 is, so never beyond float32's finite limits; NaN and
      // infinities as null, which "minimum" and "maximum" do not constrain.
      return Schema{{"type", {"number", "null"}},
                    {"minimum", -static_cast<double>(std::numeric_limits<float>::max())},
                    {"maximum", static_cast<double>(std::numeric_limits<float>::max())}};
    case ScalarKind::float64:
      return Schema{{"type", {"number", "null"}}};
    default:
      return integer_schema(kind);
  }
}

Schema enumeration_schema(const FieldType& type) {
  Schema names = Schema::array();
  Schema named_numbers = Schema::array();
  for (const EnumValue& v : type.values) {
    names.push_back(v.name);
    if (exact_in_every_reader(v.value)) named_numbers.push_back(v.value);
  }
  // A named value is always written as its name, so its number never appears.
  Schema unnamed = integer_schema(type.scalar);
  if (!named_numbers.empty()) unnamed["not"] = Schema{{"enum", named_numbers}};
  return Schema{{"anyOf", {Schema{{"type", "string"}, {"enum", names}}, unnamed}}};
}

Schema record_schema(const std::vector<TypeField>& fields);

Schema value_schema(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
      return scalar_schema(type.scalar);
    case FieldType::Kind::enumeration:
      return enumeration_schema(type);
    case FieldType::Kind::string:
      // JSON Schema's maxLength counts characters (code points; a validator counting UTF-16 units
      // counts at most two per 4-byte sequence), JsonRepresentation bounds bytes: each valid UTF-8
      // sequence of 1 to 4 bytes is one character, each invalid byte one U+FFFD, and an escape
      // (\" or \u0001) one character too. So a string of at most `bound` bytes never has more than
      // `bound` characters, and `bound` ASCII bytes have exactly that many: the bound is the
      // tightest maxLength that always holds.
      return Schema{{"type", "string"}, {"maxLength", type.bound}};
    case FieldType::Kind::array:
      return Schema{{"type", "array"},
                    {"items", value_schema(type.element.at(0))},
                    {"minItems", type.bound},
                    {"maxItems", type.bound}};
    case FieldType::Kind::sequence:
      return Schema{{"type", "array"}, {"items", value_schema(type.element.at(0))}, {"maxItems", type.bound}};
    case FieldType::Kind::record:
      return record_schema(type.fields);
  }
  return Schema::object();
}

const TypeField* find_field(const std::vector<TypeField>& fields, const std::string& name) {
  const auto found = std::find_if(fields.begin(), fields.end(), [&](const TypeField& f) { return f.name == name; });
  return found == fields.end() ? nullptr : &*found;
}

// How the selector's value that carries a conditional field appears in the JSON: the name when the
// selector is an enumeration that names it, else the number.
Schema selector_value(const TypeField& selector, std::int64_t value) {
  if (selector.type.kind == FieldType::Kind::enumeration) {
    for (const EnumValue& v : selector.type.values) {
      if (v.value == value) return v.name;
    }
  }
  return value;
}

std::string description(const TypeField& field, const std::vector<TypeField>& record) {
  std::vector<std::string> parts;
  if (!field.unit.empty()) parts.push_back("unit: " + field.unit);
  if (field.minimum || field.maximum) {
    parts.push_back("declared range: " + (field.minimum ? shortest_number_text(*field.minimum) : std::string()) + ".." +
                    (field.maximum ? shortest_number_text(*field.maximum) : std::string()) +
                    " (not enforced: values beyond it are forwarded)");
  }
  if (field.present_when) {
    const FieldPresence& when = *field.present_when;
    const TypeField* selector = find_field(record, when.selector);
    std::string value = std::to_string(when.value);
    if (selector) {
      const Schema shown = selector_value(*selector, when.value);
      if (shown.is_string()) value = shown.get<std::string>() + " (" + value + ")";
    }
    parts.push_back("present only when " + when.selector + " is " + value);
  }
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : "; ") + part;
  return text;
}

// Present exactly while the selector holds the value, absent otherwise (JsonWriter leaves it out).
// "then" names the field in "properties" (true: its schema is the record's) beside "required":
// validators in strict mode (ajv's strictRequired) refuse a "required" of a property its own schema
// object does not define.
std::optional<Schema> presence_rule(const TypeField& field, const std::vector<TypeField>& record) {
  const FieldPresence& when = *field.present_when;
  const TypeField* selector = find_field(record, when.selector);
  if (!selector) return std::nullopt;  // check_type refuses such a type; the field stays optional
  const Schema value = selector_value(*selector, when.value);
  if (value.is_number() && !exact_in_every_reader(when.value)) return std::nullopt;
  return Schema{{"if", Schema{{"properties", Schema{{when.selector, Schema{{"const", value}}}}}}},
                {"then", Schema{{"properties", Schema{{field.name, true}}}, {"required", {field.name}}}},
                {"else", Schema{{"properties", Schema{{field.name, false}}}}}};
}

Schema record_schema(const std::vector<TypeField>& fields) {
  Schema properties = Schema::object();
  Schema required = Schema::array();
  Schema presence = Schema::array();
  for (const TypeField& f : fields) {
    Schema schema = value_schema(f.type);
    const std::string text = description(f, fields);
    if (!text.empty()) schema["description"] = text;
    properties[f.name] = std::move(schema);
    if (!f.present_when) {
      required.push_back(f.name);
    } else if (auto rule = presence_rule(f, fields)) {
      presence.push_back(std::move(*rule));
    }
  }
  Schema schema{{"type", "object"},
                {"properties", std::move(properties)},
                {"required", std::move(required)},
                {"additionalProperties", false}};
  if (!presence.empty()) schema["allOf"] = std::move(presence);
  return schema;
}

}  // namespace

std::string json_schema(const ChannelType& type, std::string_view title) {
  Schema schema{{"$schema", kJsonSchemaDialect}, {"title", title}};
  schema.update(record_schema(type.fields));
  return schema.dump(-1, ' ', false, Schema::error_handler_t::replace);
}

}  // namespace cosmic

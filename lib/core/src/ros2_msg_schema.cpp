// The ROS 2 message definition of a channel type (cosmic/ros2_msg_schema.hpp).
#include "cosmic/ros2_msg_schema.hpp"

#include <cstdint>
#include <optional>
#include <set>
#include <vector>

#include "cosmic/msg_types.hpp"

namespace cosmic {
// The helpers' own namespace: unity builds merge this file with others' anonymous namespaces.
namespace ros2_msg {
namespace {

bool upper(char c) { return c >= 'A' && c <= 'Z'; }
bool lower(char c) { return c >= 'a' && c <= 'z'; }
bool digit(char c) { return c >= '0' && c <= '9'; }
bool alnum(char c) { return upper(c) || lower(c) || digit(c); }

// [first][rest_or_'_']*, without "__" and not ending in '_': rosidl's pattern for field names
// (first lowercase) and constant names (uppercase).
bool snake_name(std::string_view name, bool (*letter)(char)) {
  if (name.empty() || !letter(name.front()) || name.back() == '_') return false;
  for (std::size_t i = 1; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '_' ? name[i - 1] == '_' : !(letter(c) || digit(c))) return false;
  }
  return true;
}

bool valid_constant_name(std::string_view name) { return snake_name(name, upper); }

// "front_left" -> "FrontLeft", "obstacle-range.v2" -> "ObstacleRangeV2": each run of letters and
// digits begins with a capital; everything else separates runs and is dropped.
std::string camel_case(std::string_view name) {
  std::string out;
  bool start = true;
  for (const char c : name) {
    if (!alnum(c)) {
      start = true;
      continue;
    }
    out += start && lower(c) ? static_cast<char>(c - 'a' + 'A') : c;
    start = false;
  }
  return out;
}

// A unit as a comment rosidl reads back as the field's unit: printable ASCII without brackets or
// commas (a DBC file's Latin-1 unit, say, is left out rather than mangled).
bool unit_writable(std::string_view unit) {
  if (unit.empty()) return false;
  for (const char c : unit) {
    if (c < 0x20 || c > 0x7e || c == '[' || c == ']' || c == ',') return false;
  }
  return true;
}

class DefinitionWriter {
 public:
  explicit DefinitionWriter(std::string package) : package_(std::move(package)) {}

  // The definition of a message of `fields`, named `name` (without its package), whose nested
  // messages are named after it; empty when `problem` was set.
  std::string message(const std::vector<TypeField>& fields, const std::string& name, const std::string& where) {
    std::string body;
    std::set<std::string> constants;
    for (const TypeField& f : fields) {
      if (!field(f, name, where.empty() ? f.name : where + "." + f.name, constants, body)) return {};
    }
    return body;
  }

  // The nested messages' text, each after its separator and MSG line, in order of first use.
  std::string nested_text() const {
    std::string out;
    for (const Nested& n : nested_) out += std::string(80, '=') + "\nMSG: " + n.name + "\n" + n.body;
    return out;
  }

  void reserve_name(const std::string& name) { used_.insert(name); }
  const std::string& problem() const { return problem_; }

 private:
  struct Nested {
    std::string name;  // pkg/Name
    std::string body;
  };

  bool refuse(const std::string& where, const std::string& why) {
    problem_ = "field " + where + " " + why;
    return false;
  }

  std::string unique_name(const std::string& wanted) {
    std::string name = wanted;
    for (int n = 2; !used_.insert(name).second; ++n) name = wanted + std::to_string(n);
    return name;
  }

  bool field(const TypeField& f, const std::string& parent, const std::string& where, std::set<std::string>& constants,
             std::string& body) {
    if (f.present_when) {
      return refuse(where,
                    "is conditional (present_when, a DBC message's multiplexed signal): a ROS 2 message has no "
                    "such field, so the type has no CDR form");
    }
    if (!valid_ros2_field_name(f.name)) {
      return refuse(where, "is not a ROS 2 field name ([a-z][a-z0-9_]*, without \"__\", not ending in '_')");
    }
    // The value's own type, behind at most one array or sequence.
    const FieldType* value = &f.type;
    std::string suffix;
    std::string dimensions;  // of a multi-dimensional array, for the comment that says it is flattened
    if (f.type.kind == FieldType::Kind::array) {
      std::uint64_t length = 1;
      while (value->kind == FieldType::Kind::array) {
        length *= value->bound;
        dimensions += (dimensions.empty() ? "" : " x ") + std::to_string(value->bound);
        value = &value->element.at(0);
      }
      if (value->kind == FieldType::Kind::sequence)
        return refuse(where, "is an array of sequences, which .msg cannot write");
      // Written as one flat array: CDR writes a multi-dimensional array's elements row after row
      // with no count or padding between them, so T[a*b] reads the very bytes of T[a][b].
      suffix = "[" + std::to_string(length) + "]";
      if (f.type.element.at(0).kind != FieldType::Kind::array) dimensions.clear();
    } else if (f.type.kind == FieldType::Kind::sequence) {
      value = &f.type.element.at(0);
      if (value->kind == FieldType::Kind::array || value->kind == FieldType::Kind::sequence)
        return refuse(where, "is a sequence of arrays or sequences, which .msg cannot write");
      suffix = "[<=" + std::to_string(f.type.bound) + "]";
    }
    std::string base;
    switch (value->kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        // An enumeration is its underlying integer: a 32-bit one is an IDL enum in CDR, 4 bytes,
        // which int32 and uint32 read alike.
        base = std::string(scalar_name(value->scalar));
        break;
      case FieldType::Kind::string:
        base = "string<=" + std::to_string(value->bound);
        break;
      case FieldType::Kind::record: {
        const std::string name = unique_name(parent + camel_case(f.name));
        base = package_ + "/" + name;
        const std::size_t slot = nested_.size();
        nested_.push_back(Nested{base, {}});
        std::string nested_body = message(value->fields, name, where);
        if (!problem_.empty()) return false;
        nested_[slot].body = std::move(nested_body);
        break;
      }
      case FieldType::Kind::array:
      case FieldType::Kind::sequence:
        return refuse(where, "has no .msg form");
    }
    if (value->kind == FieldType::Kind::enumeration) enum_constants(*value, base, constants, body);
    if (!dimensions.empty()) {
      body += "# " + f.name + ": " + dimensions + " elements, row after row (one flat array: the same CDR bytes)\n";
    }
    body += base + suffix + " " + f.name;
    if (unit_writable(f.unit)) body += " # [" + f.unit + "]";
    body += "\n";
    return true;
  }

  // The named values as constants of the message, when every name is a ROS 2 constant name the
  // message has not used yet (two enumerations naming OFF would clash): the values are there to
  // read the field, the names a courtesy.
  static void enum_constants(const FieldType& type, const std::string& base, std::set<std::string>& constants,
                             std::string& body) {
    for (const EnumValue& v : type.values) {
      if (!valid_constant_name(v.name) || constants.count(v.name) != 0) return;
    }
    for (const EnumValue& v : type.values) {
      constants.insert(v.name);
      body += base + " " + v.name + "=" + std::to_string(v.value) + "\n";
    }
  }

  std::string package_;
  std::set<std::string> used_;
  std::vector<Nested> nested_;
  std::string problem_;
};

}  // namespace
}  // namespace ros2_msg

bool valid_ros2_field_name(std::string_view name) { return ros2_msg::snake_name(name, ros2_msg::lower); }

Result<Ros2MsgSchema> ros2_msg_schema(const ChannelType& type, std::string_view channel_name) {
  if (const auto problems = check_type(type); !problems.empty()) {
    return Error{"the type is not sound: " + problems.front().where + ": " + problems.front().what};
  }
  std::string package(kRos2MsgGeneratedPackage);
  std::string name = ros2_msg::camel_case(channel_name);
  if (name.empty() || !ros2_msg::upper(name.front())) name = "Channel" + name;
  if (type.source && type.source->format == TypeSource::Format::msg) {
    if (const auto own = msg_type_name(type.source->name)) {
      package = own->package;
      name = own->name;
    }
  }
  ros2_msg::DefinitionWriter writer(package);
  writer.reserve_name(name);
  std::string text = writer.message(type.fields, name, "");
  if (!writer.problem().empty()) return Error{writer.problem()};
  text += writer.nested_text();
  return Ros2MsgSchema{package + "/msg/" + name, std::move(text)};
}

}  // namespace cosmic

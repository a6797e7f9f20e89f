#include "gen_struct.hpp"

#include <set>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "gen_names.hpp"
#include "gen_struct_code.hpp"
#include "gen_struct_runtime.hpp"

namespace cosmicctl {
namespace {

using cosmic::FieldType;
using cosmic::TypeField;

const FieldType& innermost(const FieldType& type) {
  const FieldType* t = &type;
  while ((t->kind == FieldType::Kind::array || t->kind == FieldType::Kind::sequence) && !t->element.empty())
    t = &t->element.front();
  return *t;
}

bool needs_named_type(const FieldType& type) {
  const auto kind = innermost(type).kind;
  return kind == FieldType::Kind::record || kind == FieldType::Kind::enumeration;
}

// The C++ type of a field's values; `named` is the type made for its record or enumeration.
std::string cpp_type(const FieldType& type, const std::string& named) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
      return scalar_cpp_type(type.scalar);
    case FieldType::Kind::enumeration:
    case FieldType::Kind::record:
      return named;
    case FieldType::Kind::string:
      return "std::string";
    case FieldType::Kind::array:
      return "std::array<" + cpp_type(type.element.front(), named) + ", " + std::to_string(type.bound) + ">";
    case FieldType::Kind::sequence:
      return "std::vector<" + cpp_type(type.element.front(), named) + ">";
  }
  return "void";
}

std::string range_comment(const TypeField& f) {
  if (f.minimum && f.maximum) {
    return cosmic::shortest_number_text(*f.minimum) + ".." + cosmic::shortest_number_text(*f.maximum);
  }
  if (f.minimum) return ">= " + cosmic::shortest_number_text(*f.minimum);
  if (f.maximum) return "<= " + cosmic::shortest_number_text(*f.maximum);
  return "";
}

// What a member's comment says: its unit, range, bounds and condition.
std::string member_comment(const TypeField& f) {
  std::vector<std::string> parts;
  if (!f.unit.empty()) parts.push_back(comment_text(f.unit));
  if (const std::string range = range_comment(f); !range.empty()) parts.push_back(range);
  for (const FieldType* t = &f.type; t; t = t->element.empty() ? nullptr : &t->element.front()) {
    if (t->kind == FieldType::Kind::string) parts.push_back("at most " + std::to_string(t->bound) + " bytes");
    if (t->kind == FieldType::Kind::sequence) parts.push_back("at most " + std::to_string(t->bound) + " elements");
  }
  if (f.present_when) {
    parts.push_back("present only while " + f.present_when->selector + " is " + std::to_string(f.present_when->value));
  }
  std::string out;
  for (const auto& part : parts) out += (out.empty() ? "  // " : ", ") + part;
  return out;
}

std::string enum_definition(const FieldType& type, const std::string& name, const std::string& indent) {
  std::string out = indent + "enum class " + name + " : " + scalar_cpp_type(type.scalar) + " {\n";
  NameScope enumerators;
  for (const auto& v : type.values) {
    out += indent + "  " + enumerators.take(v.name) + " = " + integer_literal(v.value) + ",\n";
  }
  return out + indent + "};\n";
}

std::set<std::string> declarable_names(const std::vector<TypeField>& fields) {
  std::set<std::string> out;
  for (const auto& f : fields) out.insert(declarable(f.name));
  return out;
}

// The struct of one record (nested records within it) and, into `codec`, the functions that write
// and read it, inner records' first so each finds the ones it calls.
class StructWriter {
 public:
  std::string codec;

  // `qualified`: the struct's name from the channel's namespace ("Event::Pose"); `path`: its
  // field's path in the event, for refusals ("pose", "track[]").
  std::string record(const std::vector<TypeField>& fields, const std::string& name, const std::string& qualified,
                     const std::string& path, const std::string& indent, std::set<std::string> enclosing) {
    enclosing.insert(name);
    NameScope scope(enclosing);
    RecordCode code{qualified, {}};
    for (const auto& f : fields) code.members.push_back(scope.take(f.name));
    std::string types, bounds, members;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const TypeField& f = fields[i];
      const std::string named =
          needs_named_type(f.type) ? nested_type(f, scope, code, indent + "  ", enclosing, path, types) : "";
      bounds += bound_constants(f.type, code.members[i], scope, indent + "  ");
      const std::string type = cpp_type(f.type, named);
      members += indent + "  " +
                 (f.present_when ? "std::optional<" + type + "> " + code.members[i] + ";"
                                 : type + " " + code.members[i] + "{};") +
                 member_comment(f) + "\n";
    }
    codec += record_codec(fields, code, path);
    return indent + "struct " + name + " {\n" + types + bounds + members + indent + "};\n";
  }

 private:
  // The enumeration or record type of field `f` (of its elements, for an array or a sequence),
  // appended to `types`; its name.
  std::string nested_type(const TypeField& f, NameScope& scope, const RecordCode& parent, const std::string& indent,
                          const std::set<std::string>& enclosing, const std::string& path, std::string& types) {
    const FieldType& inner = innermost(f.type);
    if (inner.kind == FieldType::Kind::enumeration) {
      const std::string named = scope.take(camel(f.name));
      types += enum_definition(inner, named, indent);
      return named;
    }
    // Not named like one of its own members: a member cannot be named as its class.
    const std::string named = scope.take(camel(f.name), declarable_names(inner.fields));
    const std::string inner_path = path_of(path, f.name) + (&inner == &f.type ? "" : "[]");
    types += record(inner.fields, named, parent.qualified + "::" + named, inner_path, indent, enclosing);
    return named;
  }

  static std::string bound_constants(const FieldType& type, const std::string& prefix, NameScope& scope,
                                     const std::string& indent) {
    std::string out;
    std::string at = prefix;
    for (const FieldType* t = &type; t; t = t->element.empty() ? nullptr : &t->element.front()) {
      const char* suffix = t->kind == FieldType::Kind::string     ? "_max_length"
                           : t->kind == FieldType::Kind::sequence ? "_max_size"
                                                                  : nullptr;
      if (suffix) {
        out += indent + "static constexpr std::size_t " + scope.take(at + suffix) + " = " + std::to_string(t->bound) +
               ";\n";
      }
      at += "_element";
    }
    return out;
  }
};

}  // namespace

std::string type_header_name(const cosmic::ChannelSpec& channel) { return identifier(channel.name) + "_type.hpp"; }

std::string type_namespace(const cosmic::ChannelSpec& channel) {
  return "types::" + declarable(identifier(channel.name));
}

std::string generate_type_header(const cosmic::ChannelSpec& channel, const std::string& model_file) {
  const cosmic::ChannelType& type = *channel.type;
  StructWriter writer;
  const std::string event = writer.record(type.fields, "Event", "Event", "", "", {});
  return fill(kTypeHeaderTemplate, {{"MODEL", comment_text(model_file)},
                                    {"CHANNEL", channel.name},
                                    {"DESCRIBE", comment_text(cosmic::describe(type))},
                                    {"NAMESPACE", type_namespace(channel)},
                                    {"STRUCT", event},
                                    {"CODEC", writer.codec},
                                    {"MAX_SIZE", std::to_string(cosmic::max_compact_size(type))}});
}

const char* compact_header() { return kCompactHeader; }

}  // namespace cosmicctl

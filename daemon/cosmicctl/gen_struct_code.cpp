#include "gen_struct_code.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cosmic/compact_layout.hpp"

namespace cosmicctl {
namespace {

using cosmic::FieldType;
using cosmic::ScalarKind;
using cosmic::TypeField;

// One statement refusing the event at `path` when `call` (a compact::Status) is not ok.
std::string checked(const std::string& call, const std::string& path, const std::string& indent) {
  return indent + "if (const compact::Status s = " + call + "; s != compact::Status::ok) return compact::refuse(s, \"" +
         path + "\");\n";
}

std::string refusal(const std::string& condition, const char* status, const std::string& path,
                    const std::string& indent) {
  return indent + "if (" + condition + ") return compact::refuse(compact::Status::" + status + ", \"" + path + "\");\n";
}

// A double as a C++ floating literal (never an integer literal, which could overflow).
std::string double_literal(double value) {
  std::string text = cosmic::shortest_number_text(value);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

// The unsigned integer nearest `value` (>= 0), within uint64.
std::string unsigned_literal(double value) {
  if (value >= 18446744073709551616.0) return "18446744073709551615ull";
  return std::to_string(static_cast<std::uint64_t>(value)) + "ull";
}

std::string signed_literal(double value) {
  if (value >= 9223372036854775808.0) return "9223372036854775807ll";
  if (value <= -9223372036854775808.0) return "(-9223372036854775807ll - 1)";
  return integer_literal(static_cast<std::int64_t>(value)) + "ll";
}

// The declared range of an integer or float value, checked before it is written. A side at the
// kind's own limit is left out: the comparison would always hold (and -Wtype-limits says so).
std::string range_check(ScalarKind kind, const TypeField& f, const std::string& expr, const std::string& path,
                        const std::string& indent) {
  if (kind == ScalarKind::boolean || (!f.minimum && !f.maximum)) return "";
  if (!cosmic::is_integer(kind)) {
    // Written as "not within" so that NaN is refused too.
    std::string within;
    const std::string value = "static_cast<double>(" + expr + ")";
    if (f.minimum) within = value + " >= " + double_literal(*f.minimum);
    if (f.maximum) within += (within.empty() ? "" : " && ") + value + " <= " + double_literal(*f.maximum);
    return refusal("!(" + within + ")", "out_of_range", path, indent);
  }
  const auto [lowest, highest] = cosmic::scalar_limits(kind);
  const bool is_signed = cosmic::is_signed_integer(kind);
  std::string outside;
  if (f.minimum && std::ceil(*f.minimum) > lowest) {
    const double low = std::ceil(*f.minimum);
    outside = expr + " < " + (is_signed ? signed_literal(low) : unsigned_literal(low));
  }
  if (f.maximum && std::floor(*f.maximum) < highest) {
    const double high = std::floor(*f.maximum);
    outside +=
        (outside.empty() ? "" : " || ") + expr + " > " + (is_signed ? signed_literal(high) : unsigned_literal(high));
  }
  return outside.empty() ? "" : refusal(outside, "out_of_range", path, indent);
}

// The bytes of a value of `type` with zero bits: a conditional field's place while not given.
std::size_t zero_size(const FieldType& type) {
  switch (type.kind) {
    case FieldType::Kind::scalar:
    case FieldType::Kind::enumeration:
      return cosmic::scalar_size(type.scalar);
    case FieldType::Kind::string:
    case FieldType::Kind::sequence:
      return 4;
    case FieldType::Kind::array:
      return type.bound * zero_size(type.element.front());
    case FieldType::Kind::record: {
      std::size_t sum = 0;
      for (const auto& f : type.fields) sum += zero_size(f.type);
      return sum;
    }
  }
  return 0;
}

// Writes (or reads) one value of a field: `expr` is where it is, `depth` names loop variables.
class ValueCode {
 public:
  explicit ValueCode(const TypeField& field) : field_(field) {}

  std::string write(const FieldType& t, const std::string& expr, const std::string& path, int depth,
                    const std::string& indent) const {
    switch (t.kind) {
      case FieldType::Kind::scalar:
        return range_check(t.scalar, field_, expr, path, indent) + checked("w.put(" + expr + ")", path, indent);
      case FieldType::Kind::enumeration:
        return checked("w.put(" + expr + ")", path, indent);
      case FieldType::Kind::string:
        return checked("w.put_string(" + expr + ", " + std::to_string(t.bound) + ")", path, indent);
      case FieldType::Kind::array:
        return loop(expr, depth, indent,
                    write(t.element.front(), element(expr, depth), path + "[]", depth + 1, indent + "  "));
      case FieldType::Kind::sequence:
        return checked("w.put_count(" + expr + ".size(), " + std::to_string(t.bound) + ")", path, indent) +
               loop(expr, depth, indent,
                    write(t.element.front(), element(expr, depth), path + "[]", depth + 1, indent + "  "));
      case FieldType::Kind::record:
        return indent + "if (const compact::Result inner = write(w, " + expr + "); !inner) return inner;\n";
    }
    return "";
  }

  std::string read(const FieldType& t, const std::string& expr, const std::string& path, int depth,
                   const std::string& indent) const {
    switch (t.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        if (t.scalar != ScalarKind::boolean) return checked("r.get(" + expr + ")", path, indent);
        // Through a bool of its own: an element of std::vector<bool> is no bool&.
        return indent + "{\n" + indent + "  bool b = false;\n" + checked("r.get(b)", path, indent + "  ") + indent +
               "  " + expr + " = b;\n" + indent + "}\n";
      case FieldType::Kind::string:
        return checked("r.get_string(" + expr + ", " + std::to_string(t.bound) + ")", path, indent);
      case FieldType::Kind::array:
        return loop(expr, depth, indent,
                    read(t.element.front(), element(expr, depth), path + "[]", depth + 1, indent + "  "));
      case FieldType::Kind::sequence: {
        const std::string count = "n" + std::to_string(depth);
        const std::string inner = indent + "  ";
        return indent + "{\n" + inner + "std::uint32_t " + count + " = 0;\n" +
               checked("r.get_count(" + count + ", " + std::to_string(t.bound) + ")", path, inner) + inner + expr +
               ".resize(" + count + ");\n" +
               loop(expr, depth, inner,
                    read(t.element.front(), element(expr, depth), path + "[]", depth + 1, inner + "  ")) +
               indent + "}\n";
      }
      case FieldType::Kind::record:
        return indent + "if (const compact::Result inner = read(r, " + expr + "); !inner) return inner;\n";
    }
    return "";
  }

 private:
  static std::string element(const std::string& expr, int depth) { return expr + "[i" + std::to_string(depth) + "]"; }
  static std::string loop(const std::string& expr, int depth, const std::string& indent, const std::string& body) {
    const std::string i = "i" + std::to_string(depth);
    return indent + "for (std::size_t " + i + " = 0; " + i + " < " + expr + ".size(); ++" + i + ") {\n" + body +
           indent + "}\n";
  }

  const TypeField& field_;
};

// Whether the selector of conditional field `f` selects it, as a C++ condition on record `v`.
std::string selected(const TypeField& f, const std::vector<TypeField>& fields, const RecordCode& code) {
  const auto selector = std::find_if(fields.begin(), fields.end(),
                                     [&](const TypeField& s) { return s.name == f.present_when->selector; });
  const auto index = static_cast<std::size_t>(selector - fields.begin());
  return "static_cast<std::int64_t>(v." + code.members[index] + ") == " + integer_literal(f.present_when->value);
}

std::string write_field(const TypeField& f, const std::vector<TypeField>& fields, const RecordCode& code,
                        std::size_t index, const std::string& path) {
  const std::string member = "v." + code.members[index];
  const std::string where = path_of(path, f.name);
  const ValueCode value(f);
  if (!f.present_when) return value.write(f.type, member, where, 0, "  ");
  return refusal(member + " && !(" + selected(f, fields, code) + ")", "not_selected", where, "  ") + "  if (" + member +
         ") {\n" + value.write(f.type, "(*" + member + ")", where, 0, "    ") + "  } else {\n" +
         checked("w.zeros(" + std::to_string(zero_size(f.type)) + ")", where, "    ") + "  }\n";
}

std::string read_field(const TypeField& f, const std::vector<TypeField>& fields, const RecordCode& code,
                       std::size_t index, const std::string& path) {
  const std::string member = "v." + code.members[index];
  const std::string where = path_of(path, f.name);
  const ValueCode value(f);
  if (!f.present_when) return value.read(f.type, member, where, 0, "  ");
  // Read in its place always; kept only while selected.
  return "  " + member + ".emplace();\n" + value.read(f.type, "(*" + member + ")", where, 0, "  ") + "  if (!(" +
         selected(f, fields, code) + ")) " + member + ".reset();\n";
}

}  // namespace

std::string record_codec(const std::vector<TypeField>& fields, const RecordCode& code, const std::string& path) {
  std::string writes, reads;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    writes += write_field(fields[i], fields, code, i, path);
    reads += read_field(fields[i], fields, code, i, path);
  }
  return "\ninline compact::Result write([[maybe_unused]] compact::Writer& w, [[maybe_unused]] const " +
         code.qualified + "& v) noexcept {\n" + writes +
         "  return {};\n}\n\ninline compact::Result read([[maybe_unused]] compact::Reader& r, [[maybe_unused]] " +
         code.qualified + "& v) {\n" + reads + "  return {};\n}\n";
}

std::string scalar_cpp_type(ScalarKind kind) {
  switch (kind) {
    case ScalarKind::boolean:
      return "bool";
    case ScalarKind::int8:
      return "std::int8_t";
    case ScalarKind::int16:
      return "std::int16_t";
    case ScalarKind::int32:
      return "std::int32_t";
    case ScalarKind::int64:
      return "std::int64_t";
    case ScalarKind::uint8:
      return "std::uint8_t";
    case ScalarKind::uint16:
      return "std::uint16_t";
    case ScalarKind::uint32:
      return "std::uint32_t";
    case ScalarKind::uint64:
      return "std::uint64_t";
    case ScalarKind::float32:
      return "float";
    case ScalarKind::float64:
      return "double";
  }
  return "void";
}

std::string integer_literal(std::int64_t value) {
  if (value == std::numeric_limits<std::int64_t>::min()) return "(-9223372036854775807 - 1)";
  return std::to_string(value);
}

std::string path_of(const std::string& path, const std::string& name) {
  return path.empty() ? name : path + "." + name;
}

}  // namespace cosmicctl

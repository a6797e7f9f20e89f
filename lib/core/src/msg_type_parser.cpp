// Reading ROS 2 .msg files (cosmic/msg_types.hpp) line by line as rosidl_adapter.parser does:
// the file's leading comment block, then per line a comment from its first '#', an indented
// comment belonging to the definition before it, and a definition split at its first blanks into
// type, name and the rest. Values are checked as rosidl's parse_value_string checks them, so a
// file is refused where rosidl refuses it. Each problem is reported at its line and column and the
// next line is read, so one pass reports them all.
#include <algorithm>
#include <array>
#include <charconv>
#include <set>

#include "cosmic/msg_types.hpp"
#include "cosmic/units.hpp"

namespace cosmic {
// Named, then anonymous: unity builds merge this file with the other readers of cosmic_core.
namespace msg_text {
namespace {

constexpr std::array<std::string_view, 14> kPrimitives = {"bool",   "byte",  "char",   "float32", "float64",
                                                          "int8",   "uint8", "int16",  "uint16",  "int32",
                                                          "uint32", "int64", "uint64", "string"};

bool is_lower(char c) { return c >= 'a' && c <= 'z'; }
bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_primitive_name(std::string_view t) {
  return std::find(kPrimitives.begin(), kPrimitives.end(), t) != kPrimitives.end();
}

std::string_view trim_left(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  return s;
}
std::string_view trim_right(std::string_view s) {
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

// [a-z][a-z0-9_]* without "__" or a final '_': rosidl's package and field names.
bool ros_lower_name(std::string_view s) {
  if (s.empty() || !is_lower(s.front()) || s.back() == '_' || s.find("__") != std::string_view::npos) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return is_lower(c) || is_digit(c) || c == '_'; });
}

// [A-Z][A-Za-z0-9]*, after rosidl's allowance for the names it derives from services and actions.
bool ros_message_name(std::string_view s) {
  if (s.starts_with("Sample_")) s.remove_prefix(7);
  for (std::string_view suffix : {"_Request", "_Response", "_Goal", "_Result", "_Feedback"}) {
    if (s.ends_with(suffix)) s.remove_suffix(suffix.size());
  }
  if (s.empty() || !is_upper(s.front())) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return is_upper(c) || is_lower(c) || is_digit(c); });
}

// [A-Z][A-Z0-9_]* without "__" or a final '_' (rosidl: ^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$).
bool ros_constant_name(std::string_view s) {
  if (s.empty() || !is_upper(s.front()) || s.back() == '_' || s.find("__") != std::string_view::npos) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return is_upper(c) || is_digit(c) || c == '_'; });
}

// A whole number as Python's int() reads it, with int(text, 0)'s 0x, 0o and 0b prefixes (no '_').
std::optional<std::pair<bool, std::uint64_t>> parse_integer(std::string_view s) {
  bool negative = false;
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
    negative = s.front() == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0') {
    const char p = s[1];
    base = p == 'x' || p == 'X' ? 16 : p == 'o' || p == 'O' ? 8 : p == 'b' || p == 'B' ? 2 : 10;
    if (base != 10) s.remove_prefix(2);
  }
  std::uint64_t magnitude = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), magnitude, base);
  if (s.empty() || error != std::errc{} || end != s.data() + s.size()) return std::nullopt;
  return std::pair{negative, magnitude};
}

// Why `value` is not a string of `type`: quoted with " or ', a quote inside escaped with '\\'; no
// longer than the bound, counted in characters (code points) after the escapes, as Python counts.
std::optional<std::string> string_value_problem(const MsgFieldType& type, std::string_view value) {
  std::string_view inner = value;
  std::size_t escapes = 0;
  for (const char quote : {'"', '\''}) {
    if (value.empty() || value.front() != quote || value.back() != quote) continue;
    inner = value.size() >= 2 ? value.substr(1, value.size() - 2) : std::string_view{};
    for (std::size_t i = 0; i < inner.size(); ++i) {
      if (inner[i] != quote) continue;
      if (i == 0 || inner[i - 1] != '\\') return "string " + quote_value(value) + ": a quote inside it is not escaped";
      ++escapes;
    }
    break;
  }
  const auto characters =
      static_cast<std::size_t>(std::count_if(inner.begin(), inner.end(),
                                             [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; })) -
      escapes;
  if (type.string_bound != 0 && characters > type.string_bound) {
    return "string " + quote_value(value) + " is longer than its bound " + std::to_string(type.string_bound);
  }
  return std::nullopt;
}

// Why `value` is not a value of the primitive `type` (no array), as rosidl checks it; nullopt: it is.
std::optional<std::string> scalar_value_problem(const MsgFieldType& type, std::string_view value) {
  const std::string shown = quote_value(value);
  if (type.name == "bool") {
    std::string lower(value);
    std::transform(lower.begin(), lower.end(), lower.begin(), [](char c) { return is_upper(c) ? c - 'A' + 'a' : c; });
    if (lower == "true" || lower == "false" || lower == "1" || lower == "0") return std::nullopt;
    return "value " + shown + " is not a bool (true, false, 1 or 0)";
  }
  if (type.name == "float32" || type.name == "float64") {
    if (value.starts_with('+')) value.remove_prefix(1);  // Python's float() takes a '+', from_chars does not
    double d = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), d);
    // Python's float() takes a value beyond the range as an infinity; so does rosidl.
    const bool read = error == std::errc{} || error == std::errc::result_out_of_range;
    if (!value.empty() && value.front() != '+' && read && end == value.data() + value.size()) return std::nullopt;
    return "value " + shown + " is not a floating point number";
  }
  if (type.name == "string") return string_value_problem(type, value);
  const auto parsed = parse_integer(value);
  const bool is_unsigned = type.name == "byte" || type.name == "char" || type.name.starts_with('u');
  const int bits = type.name == "byte" || type.name == "char" ? 8
                   : type.name.ends_with("8")                 ? 8
                   : type.name.ends_with("16")                ? 16
                   : type.name.ends_with("32")                ? 32
                                                              : 64;
  const std::uint64_t most_positive = is_unsigned ? (bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1)
                                                  : (std::uint64_t{1} << (bits - 1)) - 1;
  const std::uint64_t most_negative = is_unsigned ? 0 : std::uint64_t{1} << (bits - 1);
  if (parsed && (parsed->first ? parsed->second <= most_negative : parsed->second <= most_positive))
    return std::nullopt;
  return "value " + shown + " is not an integer " + (is_unsigned ? "0" : "-" + std::to_string(most_negative)) + ".." +
         std::to_string(most_positive) + " (" + type.name + ")";
}

// The elements of a string array's default, quoted or not, as rosidl's parse_string_array_value_string splits them.
std::optional<std::vector<std::string_view>> string_elements(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  const auto skip_blanks = [&] {
    while (pos < s.size() && s[pos] == ' ') ++pos;
  };
  while (true) {
    skip_blanks();
    if (pos >= s.size()) return out;
    if (s[pos] == ',') return std::nullopt;
    if (s[pos] == '"' || s[pos] == '\'') {
      std::size_t end = pos + 1;
      while (end < s.size() && !(s[end] == s[pos] && s[end - 1] != '\\')) ++end;
      if (end >= s.size()) return std::nullopt;
      out.push_back(s.substr(pos, end + 1 - pos));
      pos = end + 1;
    } else {
      const std::size_t comma = std::min(s.find(',', pos), s.size());
      out.push_back(trim_right(s.substr(pos, comma - pos)));
      pos = comma;
    }
    skip_blanks();
    if (pos < s.size() && s[pos] == ',') ++pos;
  }
}

std::vector<std::string_view> split_commas(std::string_view s) {
  std::vector<std::string_view> out;
  if (s.empty()) return out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = s.find(',', start);
    out.push_back(trim_right(trim_left(s.substr(start, comma == std::string_view::npos ? s.npos : comma - start))));
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

// Why `value` is not a default of the primitive `type`, array or not; nullopt: it is.
std::optional<std::string> default_problem(const MsgFieldType& type, std::string_view value) {
  if (type.array == MsgFieldType::Array::none) return scalar_value_problem(type, value);
  if (value.size() < 2 || value.front() != '[' || value.back() != ']') {
    return "an array's default value " + quote_value(value) + " is written [A, B, ...]";
  }
  const std::string_view inside = value.substr(1, value.size() - 2);
  const auto elements = type.name == "string" ? string_elements(inside) : split_commas(inside);
  if (!elements) return "the strings of default value " + quote_value(value) + " are not quoted correctly";
  if (type.array == MsgFieldType::Array::fixed && elements->size() != type.array_size) {
    return "the array needs exactly " + std::to_string(type.array_size) + " values, not " +
           std::to_string(elements->size());
  }
  if (type.array == MsgFieldType::Array::bounded && elements->size() > type.array_size) {
    return "the array holds at most " + std::to_string(type.array_size) + " values, not " +
           std::to_string(elements->size());
  }
  MsgFieldType element = type;
  element.array = MsgFieldType::Array::none;
  for (const std::string_view e : *elements) {
    if (auto problem = scalar_value_problem(element, e)) return problem;
  }
  return std::nullopt;
}

// rosidl's unit: the text of the only "[...]" (no ',' inside, not empty) in a definition's comments.
std::string unit_of(const std::vector<std::string>& comments) {
  std::string joined;
  for (std::size_t i = 0; i < comments.size(); ++i) joined += (i ? "\n" : "") + comments[i];
  std::vector<std::string_view> found;
  const std::string_view text = joined;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '[') continue;
    std::size_t j = i + 1;
    while (j < text.size() && text[j] != ',' && text[j] != ']') ++j;
    if (j < text.size() && text[j] == ']' && j > i + 1) {
      found.push_back(text.substr(i + 1, j - i - 1));
      i = j;
    }
  }
  return found.size() == 1 ? std::string(found.front()) : std::string();
}

bool blank(char c) { return c == ' ' || c == '\t'; }

class MsgParser {
 public:
  explicit MsgParser(std::string_view text) : text_(text) {}

  MsgFile run() && {
    int number = 0;
    bool leading_comments = true;  // rosidl's file-level comment block: the message's, not a field's
    std::size_t start = 0;
    while (start <= text_.size()) {
      const std::size_t end = std::min(text_.find('\n', start), text_.size());
      std::string_view raw = text_.substr(start, end - start);
      if (raw.ends_with('\r')) raw.remove_suffix(1);
      ++number;
      if (leading_comments && raw.starts_with('#')) {
        // part of the block; nothing in it is read
      } else {
        leading_comments = false;
        line(raw, number);
      }
      if (end == text_.size()) break;
      start = end + 1;
    }
    for (std::size_t i = 0; i < file_.fields.size(); ++i) file_.fields[i].unit = unit_of(comments_[i]);
    std::stable_sort(file_.errors.begin(), file_.errors.end(), [](const auto& a, const auto& b) {
      return std::pair{a.line, a.column} < std::pair{b.line, b.column};
    });
    if (unreported_ > 0) {
      file_.errors.push_back(MsgError{0, 0, std::to_string(unreported_) + " more errors not reported"});
    }
    return std::move(file_);
  }

 private:
  // What indented comment lines belong to: the definition before them, if any.
  enum class Last { none, field, constant };

  void error(int line, int column, std::string message) {
    if (file_.errors.size() < kMaxReportedTextErrors) {
      file_.errors.push_back(MsgError{line, column, std::move(message)});
    } else {
      ++unreported_;
    }
  }

  void line(std::string_view raw, int number) {
    const std::size_t hash = raw.find('#');
    std::string_view definition = raw.substr(0, hash);
    if (hash != std::string_view::npos) {
      std::string comment(raw.substr(hash));
      comment.erase(0, comment.find_first_not_of('#'));
      std::replace(comment.begin(), comment.end(), '\t', ' ');  // rosidl reads tabs as spaces
      if (!definition.empty() && std::all_of(definition.begin(), definition.end(), blank)) {
        if (last_ == Last::field) comments_.back().push_back(std::move(comment));
        return;
      }
      pending_.push_back(std::move(comment));
    }
    while (!definition.empty() && blank(definition.back())) definition.remove_suffix(1);
    if (definition.empty()) return;
    last_ = Last::none;
    if (!control_free(definition, number)) return pending_.clear();
    if (blank(definition.front())) {
      error(number, 1, "a definition starts at the beginning of its line (rosidl refuses an indented one)");
      return pending_.clear();
    }
    definitions(definition, number);
    pending_.clear();
  }

  bool control_free(std::string_view definition, int number) {
    for (std::size_t i = 0; i < definition.size(); ++i) {
      const auto c = static_cast<unsigned char>(definition[i]);
      if ((c < 0x20 && c != '\t') || c == 0x7f) {
        error(number, static_cast<int>(i) + 1, "a control character (byte " + std::to_string(c) + ") in a definition");
        return false;
      }
    }
    return true;
  }

  // A view's column in its line (1-based), the view lying inside `line`.
  static int column_of(std::string_view line, std::string_view part) {
    return static_cast<int>(part.data() - line.data()) + 1;
  }

  void definitions(std::string_view line, int number) {
    const std::size_t space = line.find_first_of(" \t");
    const std::string_view type = line.substr(0, space);
    const std::string_view rest =
        space == std::string_view::npos ? std::string_view{} : trim_blanks(line.substr(space));
    if (rest.empty()) {
      error(number, static_cast<int>(line.size()) + 1, "expected a name after the type " + quote_value(type));
      return;
    }
    if (rest.find('=') != std::string_view::npos) return constant(line, type, rest, number);
    field(line, type, rest, number);
  }

  static std::string_view trim_blanks(std::string_view s) {
    while (!s.empty() && blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && blank(s.back())) s.remove_suffix(1);
    return s;
  }

  void field(std::string_view line, std::string_view type_text, std::string_view rest, int number) {
    const std::size_t space = rest.find_first_of(" \t");
    const std::string_view name = rest.substr(0, space);
    const std::string_view value =
        space == std::string_view::npos ? std::string_view{} : trim_blanks(rest.substr(space));
    auto type = field_type(line, type_text, number);
    bool ok = type.has_value();
    if (!ros_lower_name(name)) {
      error(number, column_of(line, name),
            quote_value(name) + " is not a field name ([a-z][a-z0-9_]*, no '__', no final '_')");
      ok = false;
    } else if (!field_names_.insert(std::string(name)).second) {
      error(number, column_of(line, name), "field " + std::string(name) + " defined twice");
      ok = false;
    }
    if (type && !value.empty()) {
      const auto problem = type->is_primitive()
                               ? default_problem(*type, value)
                               : std::optional<std::string>("a field of a message type has no default value");
      if (problem) {
        error(number, column_of(line, value), *problem);
        ok = false;
      }
    }
    if (!ok) return;
    if (file_.fields.size() >= kMsgMaxFields) {
      return error(number, 1, "more than " + std::to_string(kMsgMaxFields) + " fields in one message");
    }
    MsgField f{*type, std::string(name), std::nullopt, "", number, 1};
    if (!value.empty()) f.default_value = std::string(value);
    file_.fields.push_back(std::move(f));
    comments_.push_back(std::move(pending_));
    pending_ = {};
    last_ = Last::field;
  }

  void constant(std::string_view line, std::string_view type, std::string_view rest, int number) {
    const std::size_t equals = rest.find('=');
    const std::string_view name = trim_blanks(rest.substr(0, equals));
    const std::string_view value = trim_blanks(rest.substr(equals + 1));
    bool ok = true;
    if (!is_primitive_name(type) && type != "wstring") {
      error(
          number, 1,
          "a constant's type is bool, byte, char, float32, float64, int8..uint64 or string, not " + quote_value(type));
      ok = false;
    }
    if (!ros_constant_name(name)) {
      error(number, column_of(line, name.empty() ? rest : name),
            quote_value(name) + " is not a constant name ([A-Z][A-Z0-9_]*, no '__', no final '_')");
      ok = false;
    } else if (!constant_names_.insert(std::string(name)).second) {
      error(number, column_of(line, name), "constant " + std::string(name) + " defined twice");
      ok = false;
    }
    if (ok) {
      MsgFieldType t{"", std::string(type == "wstring" ? "string" : type), 0, MsgFieldType::Array::none, 0};
      if (auto problem = scalar_value_problem(t, value)) {
        error(number, value.empty() ? column_of(line, rest) + static_cast<int>(rest.size()) : column_of(line, value),
              *problem);
        ok = false;
      }
    }
    if (!ok) return;
    if (file_.constants.size() >= kMsgMaxConstants) {
      return error(number, 1, "more than " + std::to_string(kMsgMaxConstants) + " constants in one message");
    }
    file_.constants.push_back(MsgConstant{std::string(type), std::string(name), std::string(value), number, 1});
    last_ = Last::constant;
  }

  // A length or bound: 1..kMaxTypeBound, written in decimal.
  std::optional<std::uint32_t> bound(std::string_view text, std::string_view what, int number, int column) {
    std::uint32_t n = 0;
    const auto [end, code] = std::from_chars(text.data(), text.data() + text.size(), n);
    if (text.empty() || code != std::errc{} || end != text.data() + text.size() || n == 0) {
      error(number, column, std::string(what) + " " + quote_value(text) + " is not a whole number above 0");
      return std::nullopt;
    }
    if (n > kMaxTypeBound) {
      error(number, column,
            std::string(what) + " " + std::string(text) + " is beyond " + std::to_string(kMaxTypeBound) +
                ", the most a channel's type holds");
      return std::nullopt;
    }
    return n;
  }

  std::optional<MsgFieldType> field_type(std::string_view line, std::string_view text, int number) {
    MsgFieldType out;
    std::string_view base = text;
    if (text.ends_with(']')) {
      const std::size_t open = text.rfind('[');
      if (open == std::string_view::npos) {
        error(number, column_of(line, text), "type " + quote_value(text) + " ends with ']' but has no '['");
        return std::nullopt;
      }
      std::string_view size = text.substr(open + 1, text.size() - open - 2);
      base = text.substr(0, open);
      if (size.empty()) {
        out.array = MsgFieldType::Array::unbounded;
      } else {
        const bool upper = size.starts_with("<=");
        if (upper) size.remove_prefix(2);
        const auto n = bound(size, "array size", number, column_of(line, size));
        if (!n) return std::nullopt;
        out.array = upper ? MsgFieldType::Array::bounded : MsgFieldType::Array::fixed;
        out.array_size = *n;
      }
      if (base.find_first_of("[]") != std::string_view::npos) {
        error(number, column_of(line, text), "type " + quote_value(text) + ": ROS 2 has no arrays of arrays");
        return std::nullopt;
      }
    }
    if (!base_type(line, base, number, out)) return std::nullopt;
    return out;
  }

  bool base_type(std::string_view line, std::string_view base, int number, MsgFieldType& out) {
    const int column = column_of(line, base);
    if (base == "time" || base == "duration") {
      error(number, column,
            "ROS 1's " + std::string(base) + " is not a ROS 2 type: write builtin_interfaces/" +
                (base == "time" ? "Time" : "Duration"));
      return false;
    }
    if (base == "wstring" || base.starts_with("wstring<=")) {
      error(number, column,
            "wstring is refused: a channel's strings are bytes, and a wide string's CDR form changed between "
            "DDS-XTypes 1.1 and 1.2 (DDS implementations disagree on it); use string");
      return false;
    }
    if (is_primitive_name(base)) {
      out.name = std::string(base);
      return true;
    }
    if (base.starts_with("string<=")) {
      const auto n = bound(base.substr(8), "string bound", number, column + 8);
      if (!n) return false;
      out.name = "string";
      out.string_bound = *n;
      return true;
    }
    return message_type(base, number, column, out);
  }

  bool message_type(std::string_view base, int number, int column, MsgFieldType& out) {
    const std::size_t slash = base.find('/');
    const std::string_view package = slash == std::string_view::npos ? std::string_view{} : base.substr(0, slash);
    const std::string_view name = slash == std::string_view::npos ? base : base.substr(slash + 1);
    if (name.starts_with("msg/") && name.find('/', 4) == std::string_view::npos) {
      error(number, column,
            "type " + quote_value(base) + ": a .msg file names a message pkg/Name (rosidl reads no /msg/ there)");
      return false;
    }
    if (slash == std::string_view::npos && !base.empty() && !is_upper(base.front())) {
      error(number, column,
            quote_value(base) +
                " is neither a primitive type (bool, byte, char, float32, float64, int8..uint64, string) nor a "
                "message name ([A-Z][A-Za-z0-9]*)");
      return false;
    }
    if (slash != std::string_view::npos && !ros_lower_name(package)) {
      error(number, column, quote_value(package) + " is not a package name ([a-z][a-z0-9_]*, no '__', no final '_')");
      return false;
    }
    if (!ros_message_name(name)) {
      error(number, column + static_cast<int>(slash == std::string_view::npos ? 0 : slash + 1),
            quote_value(name) + " is not a message name ([A-Z][A-Za-z0-9]*)");
      return false;
    }
    out.package = std::string(package);
    out.name = std::string(name);
    return true;
  }

  std::string_view text_;
  MsgFile file_;
  std::vector<std::vector<std::string>> comments_;  // of each field, for its unit
  std::vector<std::string> pending_;                // whole-line comments waiting for the next definition
  Last last_ = Last::none;
  std::set<std::string> field_names_, constant_names_;
  std::size_t unreported_ = 0;
};

}  // namespace
}  // namespace msg_text

bool MsgFieldType::is_primitive() const { return !name.empty() && msg_text::is_lower(name.front()); }

MsgFile parse_msg(std::string_view text) {
  if (text.size() > kMsgMaxTextBytes) {
    MsgFile file;
    file.errors.push_back(MsgError{0, 0,
                                   "the .msg file has " + std::to_string(text.size()) +
                                       " bytes, more than the limit of " + std::to_string(kMsgMaxTextBytes)});
    return file;
  }
  return msg_text::MsgParser(text).run();
}

std::optional<MsgTypeName> msg_type_name(std::string_view text) {
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  std::string_view name = text.substr(slash + 1);
  if (name.starts_with("msg/")) name.remove_prefix(4);
  MsgTypeName out{std::string(text.substr(0, slash)), std::string(name)};
  if (!msg_text::ros_lower_name(out.package) || !msg_text::ros_message_name(out.name)) return std::nullopt;
  return out;
}

}  // namespace cosmic

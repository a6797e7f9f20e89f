// The IDL reader's declarations (idl_parser.hpp): modules, structs with their members and
// annotations, enums, typedefs, constants and the types members name (primitives, strings,
// sequences, declared types). Each problem is reported at its line and column, and the parser goes
// on at the next ';' (or the '}' closing the declaration it is in), so one pass reports them all.
#include <algorithm>

#include "cosmic/units.hpp"
#include "idl_parser.hpp"

namespace cosmic::idl_detail {
namespace {

// Words that start a declaration the reader does not read, and why.
std::optional<std::string> unread_declaration(std::string_view word) {
  if (word == "union") return "unions are not read: a channel's type has no variant fields (ROS 2 generates none)";
  for (const std::string_view other :
       {"interface", "valuetype", "eventtype", "exception", "component", "home", "porttype", "connector", "bitset",
        "bitmask", "native", "abstract", "local", "custom", "import", "typeid", "typeprefix"}) {
    if (word == other)
      return "'" + std::string(word) +
             "' declarations are not read: only modules, structs, enums, typedefs and constants are";
  }
  return std::nullopt;
}

}  // namespace

void FileParser::definitions() {
  while (peek_.kind != TokenKind::end && !(peek_.is("}") && !scope_.empty())) {
    const std::size_t before = consumed_;
    definition();
    if (consumed_ == before) advance();  // reported: a stray '}' at the top, say
  }
}

void FileParser::definition() {
  if (peek_.kind == TokenKind::directive) return directive(true);
  const std::vector<Annotation> annotations = annotation_list();
  if (peek_.is("module")) return module();
  if (peek_.is("struct")) return structure(annotations);
  if (peek_.is("enum")) return enumeration(annotations);
  if (peek_.is("typedef")) return type_definition();
  if (peek_.is("const")) return constant(annotations);
  if (peek_.kind == TokenKind::identifier) {
    if (const auto why = unread_declaration(peek_.text)) {
      error_at(peek_, *why);
      return skip_declaration();
    }
  }
  expected("a module, struct, enum, typedef or const declaration");
  skip_declaration();
}

void FileParser::module() {
  const Token keyword = advance();
  const auto name = identifier("the module's name after 'module'");
  if (!name || !take("{", "'{' after the module's name")) return skip_declaration();
  if (scope_.size() >= kIdlMaxModuleDepth) {
    error_at(keyword, "modules nested more than " + std::to_string(kIdlMaxModuleDepth) + " deep");
    skip_block();
  } else {
    scope_.push_back(*name);
    definitions();
    scope_.pop_back();
  }
  if (take("}", "'}' at the end of module " + *name)) take(";", "';' after the module's '}'");
}

// What follows a '{' up to its '}' (left for the caller), braces balanced.
void FileParser::skip_block() {
  int depth = 0;
  while (peek_.kind != TokenKind::end && !(peek_.is("}") && depth == 0)) {
    const Token t = advance();
    depth += t.is("{") ? 1 : t.is("}") ? -1 : 0;
  }
}

void FileParser::structure(const std::vector<Annotation>& annotations) {
  const Token keyword = advance();
  const auto name = identifier("the struct's name after 'struct'");
  if (!name) return skip_declaration();
  if (peek_.is(";")) {
    error_at(keyword, "forward declarations are not read: declare struct " + *name + " where it is first used");
    advance();
    return;
  }
  if (peek_.is(":")) {
    error_at(peek_, "struct inheritance is not read: give struct " + *name + " its base's members");
    return skip_declaration();
  }
  if (!take("{", "'{' after the struct's name")) return skip_declaration();
  IdlStruct s;
  s.name = scoped(*name);
  s.file = file_;
  s.line = keyword.line;
  s.column = keyword.column;
  struct_annotations(annotations, s);
  current_struct_ = s.name;
  while (peek_.kind != TokenKind::end && !peek_.is("}")) {
    const std::size_t before = consumed_;
    member(s);
    if (consumed_ == before) advance();
  }
  current_struct_.clear();
  if (!take("}", "'}' at the end of struct " + *name)) return;
  take(";", "';' after the struct's '}'");
  if (declare(s.name, IdlType::Kind::structure, keyword)) shared_.out.structs.push_back(std::move(s));
}

void FileParser::struct_annotations(const std::vector<Annotation>& annotations, IdlStruct& s) {
  for (const Annotation& a : annotations) {
    std::string kind = a.name;
    if (a.name == "extensibility") {
      const AnnotationValue* value = a.param("value");
      kind = value == nullptr ? "" : value->text;
      std::transform(kind.begin(), kind.end(), kind.begin(),
                     [](char c) { return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c; });
    }
    if (kind == "final" || kind == "appendable") {
      s.extensibility = kind == "final" ? CdrExtensibility::final_type : CdrExtensibility::appendable;
      s.extensibility_declared = true;
    } else if (kind == "mutable") {
      error(a.line, a.column,
            "@mutable types are not read: their parameter-list encodings give members ids a channel's type has not");
    } else if (a.name == "extensibility") {
      error(a.line, a.column, "@extensibility takes FINAL, APPENDABLE or MUTABLE");
    } else if (a.name == "verbatim") {
      s.comment = verbatim_comment(a);
    }
  }
}

std::string FileParser::verbatim_comment(const Annotation& a) {
  const AnnotationValue* language = a.param("language");
  const AnnotationValue* text = a.param("text");
  if (text == nullptr || (language != nullptr && language->text != "comment")) return "";
  return text->text;
}

// [annotations] TYPE name[dims] {, name[dims]} ;   (or a directive: #pragma)
void FileParser::member(IdlStruct& s) {
  if (peek_.kind == TokenKind::directive) return directive(false);
  const std::vector<Annotation> annotations = annotation_list();
  const auto type = type_spec(0);
  if (!type) return skip_declaration();
  do {
    const Token at = peek_;
    auto name = identifier("the member's name after its type");
    if (!name) return skip_declaration();
    IdlMember m;
    m.name = std::move(*name);
    m.type = *type;
    m.line = at.line;
    m.column = at.column;
    if (!dimensions(m.dimensions)) return skip_declaration();
    member_annotations(annotations, m);
    add_member(s, std::move(m), at);
  } while (peek_.is(",") && advance().is(","));
  if (!take(";", "';' after the member")) skip_declaration();
}

void FileParser::add_member(IdlStruct& s, IdlMember m, const Token& at) {
  const bool twice =
      std::any_of(s.members.begin(), s.members.end(), [&](const IdlMember& o) { return o.name == m.name; });
  if (twice) return error_at(at, "member " + m.name + " declared twice in " + s.name);
  if (s.members.size() >= kIdlMaxMembers) {
    return error_at(at, "struct " + s.name + " has more than " + std::to_string(kIdlMaxMembers) + " members");
  }
  s.members.push_back(std::move(m));
}

void FileParser::member_annotations(const std::vector<Annotation>& annotations, IdlMember& m) {
  for (const Annotation& a : annotations) {
    if (a.name == "key" && a.enabled()) {
      error(a.line, a.column, "@key makes a keyed type, which is not read: the gateway does not compute key hashes");
    } else if (a.name == "optional" && a.enabled()) {
      error(a.line, a.column, "@optional members are not read: a channel's type has no absent fields");
    } else if (a.name == "non_serialized" && a.enabled()) {
      error(a.line, a.column, "@non_serialized members are not read: the type would differ from what goes on the wire");
    } else if (a.name == "unit") {
      const AnnotationValue* value = a.param("value");
      if (value == nullptr || value->kind != AnnotationValue::Kind::string) {
        error(a.line, a.column, "@unit takes a string: @unit(\"m/s\")");
      } else {
        m.unit = value->text;
      }
    } else if (a.name == "min" || a.name == "max") {
      range_end(a, a.param("value"), a.name == "min" ? m.minimum : m.maximum);
    } else if (a.name == "range") {
      range_end(a, a.param("min"), m.minimum);
      range_end(a, a.param("max"), m.maximum);
    } else if (a.name == "default") {
      if (const AnnotationValue* value = a.param("value")) m.default_value = value->text;
    } else if (a.name == "verbatim") {
      m.comment = verbatim_comment(a);
    }
  }
}

void FileParser::range_end(const Annotation& a, const AnnotationValue* value, std::optional<double>& end) {
  if (value == nullptr)
    return error(a.line, a.column, "@" + a.name + " takes a number: @range(min=0, max=10), @min(0)");
  const auto number = annotation_number(*value);
  if (!number)
    return error(a.line, a.column, "@" + a.name + "'s value " + quote_value(value->text) + " is not a number");
  end = *number;
}

// {[N]} after a declarator; false (reported) when malformed.
bool FileParser::dimensions(std::vector<std::uint32_t>& out) {
  while (peek_.is("[")) {
    advance();
    const auto size = positive_integer("an array's size");
    if (!size || !take("]", "']' after the array's size")) return false;
    if (out.size() >= kIdlMaxDimensions) {
      error_at(peek_, "an array has more than " + std::to_string(kIdlMaxDimensions) + " dimensions");
      return false;
    }
    out.push_back(*size);
  }
  return true;
}

// A bound or array size: a positive integer literal or integer constant.
std::optional<std::uint32_t> FileParser::positive_integer(std::string_view what) {
  const Token at = peek_;
  std::optional<std::uint64_t> value;
  if (peek_.kind == TokenKind::number) {
    value = integer_literal(advance().text);
  } else if (peek_.kind == TokenKind::identifier || peek_.is("::")) {
    const auto name = scoped_name(what);
    if (!name) return std::nullopt;
    const auto* symbol = resolve(*name);
    const bool constant = symbol != nullptr && symbol->second.kind == IdlType::Kind::primitive;
    const auto& constants = shared_.out.constants;
    const IdlConstant* c =
        constant && symbol->second.index < constants.size() ? &constants[symbol->second.index] : nullptr;
    if (c != nullptr && c->type.kind == IdlType::Kind::primitive && is_integer(c->type.scalar)) {
      value = integer_literal(c->value);  // a negative one does not read: not positive
    }
  } else {
    expected(what);
    return std::nullopt;
  }
  if (!value || *value == 0 || *value > 0xFFFF'FFFFu) {
    error_at(at, std::string(what) + " " + quote_value(at.text) + " is not a positive integer of 32 bits");
    return std::nullopt;
  }
  return static_cast<std::uint32_t>(*value);
}

std::optional<IdlType> FileParser::type_spec(std::size_t depth) {
  if (depth >= kMaxTypeDepth) {
    error_at(peek_, "sequences nested more than " + std::to_string(kMaxTypeDepth) + " deep");
    return std::nullopt;
  }
  if (peek_.is("::")) return named_type();
  if (peek_.kind != TokenKind::identifier) {
    expected("a type");
    return std::nullopt;
  }
  const Token first = peek_;
  if (first.is("string") || first.is("sequence")) return template_type(depth);
  if (const auto spelled = primitive_spelling()) {
    if (spelled->empty()) return std::nullopt;  // reported
    IdlType t;
    t.name = *spelled;
    t.scalar = *idl_scalar_kind(*spelled);
    return t;
  }
  for (const std::string_view wide : {"wchar", "wstring"}) {
    if (first.is(wide)) return refuse_type("wide characters (wchar, wstring) are not read: use char and string");
  }
  if (first.is("fixed")) return refuse_type("fixed-point types are not read");
  if (first.is("map")) return refuse_type("maps are not read: a channel's type has no map");
  if (first.is("any") || first.is("Object") || first.is("ValueBase"))
    return refuse_type(quote_value(first.text) + " types are not read");
  if (first.is("struct") || first.is("union") || first.is("enum"))
    return refuse_type("a member's type is declared before its struct, not inside it");
  return named_type();
}

std::optional<IdlType> FileParser::refuse_type(std::string why) {
  error_at(peek_, std::move(why));
  return std::nullopt;
}

// The primitive spelled at peek_ (its words taken), "" when refused (reported), nullopt when no
// primitive starts here.
std::optional<std::string> FileParser::primitive_spelling() {
  if (peek_.is("unsigned")) {
    advance();
    if (peek_.is("short")) return (advance(), std::string("unsigned short"));
    if (!peek_.is("long")) return (expected("'short' or 'long' after 'unsigned'"), std::string());
    advance();
    if (peek_.is("long")) return (advance(), std::string("unsigned long long"));
    return std::string("unsigned long");
  }
  if (peek_.is("long")) {
    advance();
    if (peek_.is("long")) return (advance(), std::string("long long"));
    if (peek_.is("double")) {
      error_at(peek_, "long double is not read: a channel's type has no 128-bit float");
      return (advance(), std::string());
    }
    return std::string("long");
  }
  if (peek_.kind == TokenKind::identifier && idl_scalar_kind(peek_.text)) return std::string(advance().text);
  return std::nullopt;
}

// string, string<N>, sequence<T>, sequence<T, N>.
std::optional<IdlType> FileParser::template_type(std::size_t depth) {
  IdlType t;
  t.kind = advance().is("string") ? IdlType::Kind::string : IdlType::Kind::sequence;
  if (t.kind == IdlType::Kind::string && !peek_.is("<")) return t;
  if (!take("<", t.kind == IdlType::Kind::string ? "'<'" : "'<' after 'sequence'")) return std::nullopt;
  bool bounded = t.kind == IdlType::Kind::string;
  if (t.kind == IdlType::Kind::sequence) {
    auto element = type_spec(depth + 1);
    if (!element) return std::nullopt;
    t.element.push_back(std::move(*element));
    bounded = peek_.is(",") && advance().is(",");
  }
  if (bounded) {
    const auto bound = positive_integer(t.kind == IdlType::Kind::string ? "a string's bound" : "a sequence's bound");
    if (!bound) return std::nullopt;
    t.bound = *bound;
  }
  if (!take(">", "'>'")) return std::nullopt;
  return t;
}

std::optional<IdlType> FileParser::named_type() {
  const Token at = peek_;
  const auto name = scoped_name("a type");
  if (!name) return std::nullopt;
  const auto* symbol = resolve(*name);
  if (symbol == nullptr) {
    const bool itself =
        !current_struct_.empty() && (current_struct_ == *name || current_struct_.ends_with("::" + *name));
    error_at(at, itself ? "struct " + current_struct_ + " contains itself: a channel's type is finite"
                        : "type " + quote_value(*name) + " is not declared before its use" +
                              (shared_.out.includes.empty() ? "" : " (nor in the files included)"));
    return std::nullopt;
  }
  const IdlType::Kind kind = symbol->second.kind;
  if (kind != IdlType::Kind::structure && kind != IdlType::Kind::enumeration && kind != IdlType::Kind::alias) {
    error_at(at, quote_value(*name) + " is " + std::string(symbol_word(kind)) + ", not a type");
    return std::nullopt;
  }
  IdlType t;
  t.kind = kind;
  t.name = symbol->first;
  return t;
}

// enum NAME { [@value(N)] A, B, ... } ;
void FileParser::enumeration(const std::vector<Annotation>& annotations) {
  const Token keyword = advance();
  for (const Annotation& a : annotations) {
    const AnnotationValue* bits = a.param("value");
    if (a.name == "bit_bound" && (bits == nullptr || bits->text != "32")) {
      error(a.line, a.column, "@bit_bound other than 32 is not read: an IDL enum is a 32-bit integer here");
    }
  }
  const auto name = identifier("the enum's name after 'enum'");
  if (!name || !take("{", "'{' after the enum's name")) return skip_declaration();
  IdlEnum e;
  e.name = scoped(*name);
  e.file = file_;
  e.line = keyword.line;
  e.column = keyword.column;
  std::int64_t next = 0;
  do {
    const std::vector<Annotation> value_annotations = annotation_list();
    const Token at = peek_;
    const auto value_name = identifier("an enumerator's name");
    if (!value_name) return skip_declaration();
    std::int64_t value = next;
    for (const Annotation& a : value_annotations) {
      if (a.name == "value") enumerator_value(a, value);
    }
    if (e.values.size() >= kMaxEnumValues) {
      error_at(at, "enum " + e.name + " has more than " + std::to_string(kMaxEnumValues) + " values");
    } else if (declare(scoped(*value_name), IdlType::Kind::string, at)) {
      e.values.push_back(EnumValue{*value_name, value});
    }
    next = value + 1;
  } while (peek_.is(",") && advance().is(","));
  if (!take("}", "'}' at the end of enum " + *name)) return skip_declaration();
  take(";", "';' after the enum's '}'");
  if (declare(e.name, IdlType::Kind::enumeration, keyword)) shared_.out.enums.push_back(std::move(e));
}

void FileParser::enumerator_value(const Annotation& a, std::int64_t& value) {
  const AnnotationValue* given = a.param("value");
  const bool negative = given != nullptr && given->text.starts_with("-");
  const auto magnitude = given == nullptr || given->kind != AnnotationValue::Kind::number
                             ? std::nullopt
                             : integer_literal(std::string_view(given->text).substr(negative ? 1 : 0));
  const auto text = magnitude ? integer_value_text(ScalarKind::int32, *magnitude, negative) : std::nullopt;
  if (!text) return error(a.line, a.column, "@value takes an integer that int32 holds");
  value = negative ? -static_cast<std::int64_t>(*magnitude) : static_cast<std::int64_t>(*magnitude);
}

// typedef TYPE name[dims] {, name[dims]} ;
void FileParser::type_definition() {
  advance();
  const auto type = type_spec(0);
  if (!type) return skip_declaration();
  do {
    const Token at = peek_;
    const auto name = identifier("the typedef's name");
    if (!name) return skip_declaration();
    IdlTypedef t{scoped(*name), *type, {}, file_, at.line, at.column};
    if (!dimensions(t.dimensions)) return skip_declaration();
    if (declare(t.name, IdlType::Kind::alias, at)) shared_.out.typedefs.push_back(std::move(t));
  } while (peek_.is(",") && advance().is(","));
  if (!take(";", "';' after the typedef")) skip_declaration();
}

// const TYPE NAME = LITERAL ;
void FileParser::constant(const std::vector<Annotation>& annotations) {
  advance();
  const Token type_at = peek_;
  const auto type = type_spec(0);
  if (!type) return skip_declaration();
  const Token at = peek_;
  const auto name = identifier("the constant's name");
  if (!name || !take("=", "'=' after the constant's name")) return skip_declaration();
  const bool usable = type->kind == IdlType::Kind::string || type->kind == IdlType::Kind::primitive;
  if (!usable) {
    error_at(type_at, "a constant is an integer, float, boolean or string, not " + quote_value(type->name));
    return skip_declaration();
  }
  const auto value = constant_value(*type);
  if (!value) return skip_declaration();
  if (!take(";", "';' after the constant's value (a literal: expressions are not read)")) return skip_declaration();
  IdlConstant c{scoped(*name), *type, *value, "", file_, at.line, at.column};
  for (const Annotation& a : annotations) {
    if (a.name == "verbatim") c.comment = verbatim_comment(a);
  }
  if (declare(c.name, IdlType::Kind::primitive, at)) shared_.out.constants.push_back(std::move(c));
}

std::optional<std::string> FileParser::constant_value(const IdlType& type) {
  const Token at = peek_;
  if (type.kind == IdlType::Kind::string) {
    const auto text = strings();
    if (!text) return std::nullopt;
    if (type.bound != 0 && text->size() > type.bound) {
      error_at(at, "the string has " + std::to_string(text->size()) + " characters, more than its bound " +
                       std::to_string(type.bound));
      return std::nullopt;
    }
    return text;
  }
  if (type.scalar == ScalarKind::boolean) {
    if (peek_.is("TRUE") || peek_.is("FALSE")) return std::string(advance().text);
    expected("TRUE or FALSE");
    return std::nullopt;
  }
  const bool negative = peek_.is("-") && advance().is("-");
  if (peek_.kind != TokenKind::number) {
    expected("the constant's value (a literal)");
    return std::nullopt;
  }
  const Token literal = advance();
  if (!is_integer(type.scalar)) return float_value(type, literal, negative);
  const auto magnitude = integer_literal(literal.text);
  const auto text = magnitude ? integer_value_text(type.scalar, *magnitude, negative) : std::nullopt;
  if (!text)
    error_at(at, quote_value(std::string(negative ? "-" : "") + std::string(literal.text)) + " is not a value " +
                     type.name + " holds");
  return text;
}

std::optional<std::string> FileParser::float_value(const IdlType& type, const Token& literal, bool negative) {
  const auto value = float_literal(literal.text);
  const double limit = type.scalar == ScalarKind::float32 ? scalar_limits(ScalarKind::float32).second
                                                          : scalar_limits(ScalarKind::float64).second;
  if (!value || *value > limit) {
    error_at(literal, quote_value(literal.text) + " is not a value " + type.name + " holds");
    return std::nullopt;
  }
  return std::string(negative ? "-" : "") + std::string(literal.text);
}

// One or more adjacent string literals, joined.
std::optional<std::string> FileParser::strings() {
  if (peek_.kind != TokenKind::string) {
    expected("a string");
    return std::nullopt;
  }
  std::string out;
  while (peek_.kind == TokenKind::string) {
    const Token t = advance();
    const auto text = string_literal(t.text);
    if (!text) {
      error_at(t, "the string holds an unknown escape or a NUL character");
      return std::nullopt;
    }
    out += *text;
  }
  return out;
}

}  // namespace cosmic::idl_detail

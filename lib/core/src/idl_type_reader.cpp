// The IDL reader's plumbing (idl_parser.hpp): tokens and located errors, scoped names and their
// resolution, annotations, the preprocessor lines it reads (#include through the caller's loader,
// #pragma, the include guard) and the entry points of cosmic/idl_types.hpp. Names are resolved as
// they are read, since IDL declares before use: a name is looked up in the enclosing modules,
// innermost first. An #include reads the named file with a parser of its own, sharing the
// declarations; each file's errors are sorted by position.
#include <algorithm>

#include "cosmic/units.hpp"
#include "idl_parser.hpp"

namespace cosmic::idl_detail {
namespace {

std::string join(const std::vector<std::string>& scope, std::size_t count, std::string_view name) {
  std::string out;
  for (std::size_t i = 0; i < count; ++i) out += scope[i] + "::";
  return out + std::string(name);
}

}  // namespace

std::string_view symbol_word(IdlType::Kind kind) {
  switch (kind) {
    case IdlType::Kind::structure:
      return "a struct";
    case IdlType::Kind::enumeration:
      return "an enum";
    case IdlType::Kind::alias:
      return "a typedef";
    case IdlType::Kind::primitive:
      return "a constant";
    default:
      return "an enumerator";
  }
}

void FileParser::run() {
  definitions();
  if (const auto& failure = lexer_.failure()) error(failure->line, failure->column, failure->message);
  if (guard_open_) error(guard_line_, 1, "the include guard's #ifndef has no #endif");
  std::stable_sort(errors_.begin(), errors_.end(), [](const IdlError& a, const IdlError& b) {
    return std::pair{a.line, a.column} < std::pair{b.line, b.column};
  });
  for (IdlError& e : errors_) shared_.out.errors.push_back(std::move(e));
}

Token FileParser::advance() {
  const Token previous = peek_;
  peek_ = lexer_.next();
  ++consumed_;
  return previous;
}

void FileParser::error(int line, int column, std::string message) {
  if (shared_.reported < kMaxReportedTextErrors) {
    ++shared_.reported;
    errors_.push_back(IdlError{file_, line, column, std::move(message)});
  } else {
    ++shared_.unreported;
  }
}

void FileParser::error_at(const Token& t, std::string message) { error(t.line, t.column, std::move(message)); }

void FileParser::expected(std::string_view what) {
  error_at(peek_, "expected " + std::string(what) +
                      (peek_.kind == TokenKind::end ? ", found the end of the text" : ", found " + found(peek_)));
}

std::string FileParser::found(const Token& t) {
  if (t.kind == TokenKind::string) return "a string";
  if (t.kind == TokenKind::directive) return "a # directive";
  return quote_value(t.text);
}

bool FileParser::take(std::string_view punct, std::string_view what) {
  if (peek_.is(punct)) {
    advance();
    return true;
  }
  expected(what);
  return false;
}

// Past the next ';' outside braces, or up to a '}' closing what the declaration is in.
void FileParser::skip_declaration() {
  int depth = 0;
  while (peek_.kind != TokenKind::end) {
    if (peek_.is("}") && depth == 0) return;
    const Token t = advance();
    if (t.is("{")) ++depth;
    if (t.is("}")) --depth;
    if (t.is(";") && depth == 0) return;
  }
}

// An identifier, an IDL escaped one ("_struct") without its underscore.
std::optional<std::string> FileParser::identifier(std::string_view what) {
  if (peek_.kind != TokenKind::identifier) {
    expected(what);
    return std::nullopt;
  }
  std::string_view name = advance().text;
  if (name.size() > 1 && name[0] == '_') name.remove_prefix(1);
  return std::string(name);
}

// NAME {:: NAME}, maybe with a leading "::" (kept).
std::optional<std::string> FileParser::scoped_name(std::string_view what) {
  std::string name;
  if (peek_.is("::")) name = std::string(advance().text);
  auto part = identifier(what);
  if (!part) return std::nullopt;
  name += *part;
  while (peek_.is("::")) {
    advance();
    part = identifier("a name after '::'");
    if (!part) return std::nullopt;
    name += "::" + *part;
  }
  return name;
}

std::string FileParser::scoped(std::string_view name) const { return join(scope_, scope_.size(), name); }

// A name as the scopes enclosing the use see it: the innermost enclosing module first.
const std::pair<const std::string, Symbol>* FileParser::resolve(const std::string& name) const {
  if (name.starts_with("::")) {
    const auto hit = shared_.symbols.find(name.substr(2));
    return hit == shared_.symbols.end() ? nullptr : &*hit;
  }
  for (std::size_t count = scope_.size() + 1; count-- > 0;) {
    const auto hit = shared_.symbols.find(join(scope_, count, name));
    if (hit != shared_.symbols.end()) return &*hit;
  }
  return nullptr;
}

// Registers a declaration's scoped name; false (reported) when it cannot be.
bool FileParser::declare(const std::string& name, IdlType::Kind kind, const Token& at) {
  if (shared_.declarations >= kIdlMaxDeclarations) {
    error_at(at, "more than " + std::to_string(kIdlMaxDeclarations) +
                     " declarations (the limit of a file and its includes)");
    return false;
  }
  // Its index in the list its kind goes to: the caller appends it right after.
  const IdlTypeFile& out = shared_.out;
  const std::size_t index = kind == IdlType::Kind::structure     ? out.structs.size()
                            : kind == IdlType::Kind::enumeration ? out.enums.size()
                            : kind == IdlType::Kind::alias       ? out.typedefs.size()
                                                                 : out.constants.size();
  const auto [it, fresh] = shared_.symbols.emplace(name, Symbol{kind, index, file_, at.line, at.column});
  if (!fresh) {
    const Symbol& first = it->second;
    error_at(at, name + " is declared twice (first as " + std::string(symbol_word(first.kind)) + " at " +
                     (first.file.empty() ? "" : first.file + ":") + std::to_string(first.line) + ":" +
                     std::to_string(first.column) + ")");
    return false;
  }
  ++shared_.declarations;
  return true;
}

std::vector<Annotation> FileParser::annotation_list() {
  std::vector<Annotation> out;
  while (peek_.is("@")) {
    const Token at = advance();
    const auto name = scoped_name("the annotation's name after '@'");
    if (!name) break;
    Annotation a{*name, at.line, at.column, {}};
    if (peek_.is("(") && !annotation_params(a)) break;
    out.push_back(std::move(a));
  }
  return out;
}

bool FileParser::annotation_params(Annotation& a) {
  advance();
  while (!peek_.is(")")) {
    std::string key;
    if (peek_.kind == TokenKind::identifier) {
      const Token word = advance();
      if (peek_.is("=")) {
        advance();
        key = std::string(word.text);
      } else {
        a.params.emplace_back("", AnnotationValue{AnnotationValue::Kind::name, std::string(word.text)});
        if (!peek_.is(",")) break;
        advance();
        continue;
      }
    }
    const auto value = annotation_value();
    if (!value) return false;
    a.params.emplace_back(std::move(key), std::move(*value));
    if (!peek_.is(",")) break;
    advance();
  }
  return take(")", "')' after the annotation's values");
}

std::optional<AnnotationValue> FileParser::annotation_value() {
  if (peek_.kind == TokenKind::string) {
    auto text = strings();
    if (!text) return std::nullopt;
    return AnnotationValue{AnnotationValue::Kind::string, std::move(*text)};
  }
  const bool negative = peek_.is("-") && advance().is("-");
  if (peek_.kind == TokenKind::number) {
    return AnnotationValue{AnnotationValue::Kind::number,
                           std::string(negative ? "-" : "") + std::string(advance().text)};
  }
  if (!negative && (peek_.kind == TokenKind::identifier || peek_.is("::"))) {
    auto name = scoped_name("a value");
    if (!name) return std::nullopt;
    return AnnotationValue{AnnotationValue::Kind::name, std::move(*name)};
  }
  expected("an annotation's value (a number, a string or a name)");
  return std::nullopt;
}

// #include, #pragma and the include guard; any other directive is refused.
void FileParser::directive(bool may_include) {
  const Token at = advance();
  std::string_view rest = at.text;
  const std::string_view word = take_word(rest);
  const bool first = !seen_directive_;
  seen_directive_ = true;
  if (word.empty() && rest.empty()) return;  // a lone '#' is a null directive
  if (word == "include") {
    if (!may_include || !scope_.empty()) {
      return error_at(at, "an #include inside a module or struct is not read: put it at the top of the file");
    }
    return include(at, rest);
  }
  if (word == "pragma") {
    if (take_word(rest) == "keylist") {
      error_at(at, "#pragma keylist declares keys: keyed types are not read (the gateway does not compute key hashes)");
    }
    return;  // other pragmas say nothing about the type
  }
  if (include_guard(at, word, rest, first)) return;
  error_at(at, "#" + std::string(word) +
                   " is not read: this is no preprocessor (only #include, #pragma and an include guard are read)");
}

// The first word of `rest` (identifier characters), taken with the blanks around it.
std::string_view FileParser::take_word(std::string_view& rest) {
  const auto skip_blanks = [&rest] {
    while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
  };
  skip_blanks();
  std::size_t n = 0;
  while (n < rest.size() && idl_identifier_char(rest[n])) ++n;
  const std::string_view word = rest.substr(0, n);
  rest.remove_prefix(n);
  skip_blanks();
  return word;
}

// #ifndef X and #define X as the file's first directives, before any declaration, and #endif as
// its last token: what idlc needs to read a file included twice, a no-op for this reader, which
// reads each file once.
bool FileParser::include_guard(const Token& at, std::string_view word, std::string_view rest, bool first) {
  std::string_view name_rest = rest;
  const std::string_view name = take_word(name_rest);
  const bool lone_name = !name.empty() && ends_line(name_rest);
  if (word == "ifndef" && first && lone_name && shared_declarations_at_start_ == shared_.declarations) {
    guard_ = std::string(name);
    guard_line_ = at.line;
    return expect_guard_define();
  }
  if (word == "endif" && guard_open_ && ends_line(rest) && peek_.kind == TokenKind::end) {
    guard_open_ = false;
    return true;
  }
  return false;
}

bool FileParser::expect_guard_define() {
  if (peek_.kind == TokenKind::directive) {
    std::string_view rest = peek_.text;
    const bool define = take_word(rest) == "define";
    const std::string_view name = take_word(rest);
    if (define && name == guard_ && ends_line(rest)) {
      advance();
      guard_open_ = true;
      return true;
    }
  }
  return false;
}

// Nothing but a comment left on a directive's line.
bool FileParser::ends_line(std::string_view rest) {
  return rest.empty() || rest.starts_with("//") || rest.starts_with("/*");
}

// #include "NAME" or <NAME>: recorded, and read through the loader once.
void FileParser::include(const Token& at, std::string_view rest) {
  const char close = rest.starts_with("\"") ? '"' : rest.starts_with("<") ? '>' : '\0';
  const std::size_t end = close == '\0' ? std::string_view::npos : rest.find(close, 1);
  if (end == std::string_view::npos || end == 1 || !ends_line(trimmed(rest.substr(end + 1)))) {
    return error_at(at, "expected #include \"FILE\" or #include <FILE>");
  }
  const std::string name(rest.substr(1, end - 1));
  if (std::find(shared_.out.includes.begin(), shared_.out.includes.end(), name) == shared_.out.includes.end()) {
    shared_.out.includes.push_back(name);
  }
  if (!shared_.load) return;  // recorded only: the caller reads nothing
  if (std::find(shared_.reading.begin(), shared_.reading.end(), name) != shared_.reading.end()) {
    return error_at(at, "#include cycle: " + quote_value(name) + " includes itself");
  }
  if (!shared_.read.insert(name).second) return;  // read once, the first time
  if (depth_ + 1 > kIdlMaxIncludeDepth || shared_.read.size() > kIdlMaxFiles) {
    return error_at(at, "more than " +
                            std::to_string(depth_ + 1 > kIdlMaxIncludeDepth ? kIdlMaxIncludeDepth : kIdlMaxFiles) +
                            (depth_ + 1 > kIdlMaxIncludeDepth ? " files including each other" : " included files"));
  }
  read_included(at, name);
}

std::string_view FileParser::trimmed(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  return text;
}

void FileParser::read_included(const Token& at, const std::string& name) {
  const std::optional<std::string> text = shared_.load(name);
  if (!text) return error_at(at, "cannot read the included file " + quote_value(name));
  if (text->size() > kIdlMaxTextBytes || shared_.total_bytes + text->size() > kIdlMaxTotalBytes) {
    return error_at(at, "the included file " + quote_value(name) + " has " + std::to_string(text->size()) +
                            " bytes, beyond the limit of " +
                            std::to_string(text->size() > kIdlMaxTextBytes ? kIdlMaxTextBytes : kIdlMaxTotalBytes) +
                            (text->size() > kIdlMaxTextBytes ? " of one file" : " of a file and its includes"));
  }
  shared_.total_bytes += text->size();
  shared_.reading.push_back(name);
  // Its errors go before ours: flushed when it ends, ours when this file ends.
  FileParser(shared_, name, *text, depth_ + 1).run();
  shared_.reading.pop_back();
}

}  // namespace cosmic::idl_detail

namespace cosmic {

std::optional<ScalarKind> idl_scalar_kind(std::string_view name) {
  static const std::map<std::string_view, ScalarKind> kinds = {
      {"boolean", ScalarKind::boolean}, {"octet", ScalarKind::uint8},
      {"char", ScalarKind::int8},       {"int8", ScalarKind::int8},
      {"uint8", ScalarKind::uint8},     {"short", ScalarKind::int16},
      {"int16", ScalarKind::int16},     {"unsigned short", ScalarKind::uint16},
      {"uint16", ScalarKind::uint16},   {"long", ScalarKind::int32},
      {"int32", ScalarKind::int32},     {"unsigned long", ScalarKind::uint32},
      {"uint32", ScalarKind::uint32},   {"long long", ScalarKind::int64},
      {"int64", ScalarKind::int64},     {"unsigned long long", ScalarKind::uint64},
      {"uint64", ScalarKind::uint64},   {"float", ScalarKind::float32},
      {"double", ScalarKind::float64},
  };
  const auto hit = kinds.find(name);
  return hit == kinds.end() ? std::nullopt : std::optional<ScalarKind>(hit->second);
}

namespace {

template <typename T>
const T* idl_find_named(const std::vector<T>& all, std::string_view name) {
  if (name.starts_with("::")) name.remove_prefix(2);
  const auto hit = std::find_if(all.begin(), all.end(), [&](const T& each) { return each.name == name; });
  return hit == all.end() ? nullptr : &*hit;
}

}  // namespace

const IdlStruct* IdlTypeFile::find(std::string_view name) const { return idl_find_named(structs, name); }
const IdlEnum* IdlTypeFile::find_enum(std::string_view name) const { return idl_find_named(enums, name); }
const IdlTypedef* IdlTypeFile::find_typedef(std::string_view name) const { return idl_find_named(typedefs, name); }
const IdlConstant* IdlTypeFile::find_constant(std::string_view name) const { return idl_find_named(constants, name); }

IdlTypeFile parse_idl_types(std::string_view text, const IdlIncludeLoader& load) {
  idl_detail::Shared shared{{}, load, {}, {}, {}, text.size(), 0, 0, 0};
  if (text.size() > kIdlMaxTextBytes) {
    shared.out.errors.push_back(IdlError{"", 0, 0,
                                         "the IDL file has " + std::to_string(text.size()) +
                                             " bytes, more than the limit of " + std::to_string(kIdlMaxTextBytes)});
    return std::move(shared.out);
  }
  idl_detail::FileParser(shared, "", text, 0).run();
  if (shared.unreported > 0) {
    shared.out.errors.push_back(IdlError{"", 0, 0, std::to_string(shared.unreported) + " more errors not reported"});
  }
  return std::move(shared.out);
}

}  // namespace cosmic

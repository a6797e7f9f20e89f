// The parser of the IDL reader (cosmic/idl_types.hpp), one per file read: the text given to
// parse_idl_types() and each file it #includes, all sharing one Shared. Internal to cosmic_core's
// IDL reader; used by one thread, within one parse_idl_types() call. Its work is split in two:
//   idl_type_reader.cpp  tokens, names, annotations, preprocessor lines and includes, the entry points;
//   idl_type_parser.cpp  the declarations: modules, structs and members, enums, typedefs, constants, types.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/idl_types.hpp"
#include "idl_lexer.hpp"
#include "idl_syntax.hpp"

namespace cosmic::idl_detail {

// A declared name: what it is and where it was declared (for "declared twice").
struct Symbol {
  IdlType::Kind kind = IdlType::Kind::structure;  // primitive: a constant; string: an enumerator
  std::size_t index = 0;                          // in IdlTypeFile's structs, enums, typedefs or constants
  std::string file;
  int line = 0, column = 0;
};

// What the parsers of one text and its included files share.
struct Shared {
  IdlTypeFile out;
  const IdlIncludeLoader& load;
  std::map<std::string, Symbol> symbols;  // by scoped name
  std::set<std::string> read;             // included files read or being read
  std::vector<std::string> reading;       // included files being read, outermost first
  std::size_t total_bytes = 0;
  std::size_t declarations = 0;
  std::size_t unreported = 0;
  // Errors kept by every file's parser, passed on or still pending: an included file is parsed
  // while its includer's errors wait, so the limit counts both.
  std::size_t reported = 0;
};

// "a struct", "a constant", ... for a Symbol's kind.
std::string_view symbol_word(IdlType::Kind kind);

class FileParser {
 public:
  FileParser(Shared& shared, std::string file, std::string_view text, std::size_t depth)
      : shared_(shared), file_(std::move(file)), lexer_(text), depth_(depth) {
    shared_declarations_at_start_ = shared_.declarations;
    advance();
  }

  // Reads the whole file, its errors sorted by position into shared.out.errors.
  void run();

 private:
  // Tokens and errors (idl_type_reader.cpp).
  Token advance();
  void error(int line, int column, std::string message);
  void error_at(const Token& t, std::string message);
  void expected(std::string_view what);
  static std::string found(const Token& t);
  bool take(std::string_view punct, std::string_view what);
  void skip_declaration();
  std::optional<std::string> identifier(std::string_view what);
  std::optional<std::string> scoped_name(std::string_view what);

  // Names.
  std::string scoped(std::string_view name) const;
  const std::pair<const std::string, Symbol>* resolve(const std::string& name) const;
  bool declare(const std::string& name, IdlType::Kind kind, const Token& at);

  // Annotations.
  std::vector<Annotation> annotation_list();
  bool annotation_params(Annotation& a);
  std::optional<AnnotationValue> annotation_value();

  // Preprocessor lines.
  void directive(bool may_include);
  static std::string_view take_word(std::string_view& rest);
  bool include_guard(const Token& at, std::string_view word, std::string_view rest, bool first);
  bool expect_guard_define();
  static bool ends_line(std::string_view rest);
  void include(const Token& at, std::string_view rest);
  static std::string_view trimmed(std::string_view text);
  void read_included(const Token& at, const std::string& name);

  // Declarations (idl_type_parser.cpp).
  void definitions();
  void definition();
  void module();
  void skip_block();
  void structure(const std::vector<Annotation>& annotations);
  void struct_annotations(const std::vector<Annotation>& annotations, IdlStruct& s);
  static std::string verbatim_comment(const Annotation& a);
  void member(IdlStruct& s);
  void add_member(IdlStruct& s, IdlMember m, const Token& at);
  void member_annotations(const std::vector<Annotation>& annotations, IdlMember& m);
  void range_end(const Annotation& a, const AnnotationValue* value, std::optional<double>& end);
  bool dimensions(std::vector<std::uint32_t>& out);
  std::optional<std::uint32_t> positive_integer(std::string_view what);

  // Types, enums, typedefs and constants.
  std::optional<IdlType> type_spec(std::size_t depth);
  std::optional<IdlType> refuse_type(std::string why);
  std::optional<std::string> primitive_spelling();
  std::optional<IdlType> template_type(std::size_t depth);
  std::optional<IdlType> named_type();
  void enumeration(const std::vector<Annotation>& annotations);
  void enumerator_value(const Annotation& a, std::int64_t& value);
  void type_definition();
  void constant(const std::vector<Annotation>& annotations);
  std::optional<std::string> constant_value(const IdlType& type);
  std::optional<std::string> float_value(const IdlType& type, const Token& literal, bool negative);
  std::optional<std::string> strings();

  Shared& shared_;
  std::string file_;
  Lexer lexer_;
  std::size_t depth_;
  Token peek_;
  std::size_t consumed_ = 0;
  std::vector<std::string> scope_;
  std::string current_struct_;
  std::vector<IdlError> errors_;
  std::size_t shared_declarations_at_start_ = 0;  // shared_.declarations when this file began
  bool seen_directive_ = false, guard_open_ = false;
  std::string guard_;
  int guard_line_ = 0;
};

}  // namespace cosmic::idl_detail

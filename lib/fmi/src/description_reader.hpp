// The reader behind parse_model_description() (cosmic/fmi_description.hpp), shared by the files
// that read the document's parts: problems with their lines, and typed attributes.
#pragma once

#include <tinyxml2.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "cosmic/fmi_description.hpp"

namespace cosmic::fmi::detail {

class DescriptionReader {
 public:
  explicit DescriptionReader(FmuDescription& out) : out_(out) {}

  void problem(int line, std::string message);
  std::size_t problem_count() const { return problems_.size() + suppressed_; }
  std::vector<DescriptionProblem> take_problems();

  // The attribute's text, or nullopt after reporting it missing (or empty where `allow_empty` is false).
  std::optional<std::string> required(const tinyxml2::XMLElement& e, const char* name, bool allow_empty = false);
  // The attribute's text; empty when absent.
  static std::string text(const tinyxml2::XMLElement& e, const char* name);
  // A boolean attribute (true, false, 1, 0); `fallback` when absent or after reporting a bad value.
  bool flag(const tinyxml2::XMLElement& e, const char* name, bool fallback = false);
  // A decimal number; none when absent or after reporting a bad value.
  std::optional<double> number(const tinyxml2::XMLElement& e, const char* name);
  std::optional<std::int64_t> whole_number(const tinyxml2::XMLElement& e, const char* name);
  std::optional<std::uint64_t> unsigned_number(const tinyxml2::XMLElement& e, const char* name, std::uint64_t max);

  // The document's parts (fmi_variables.cpp).
  void read_type_definitions(const tinyxml2::XMLElement& list);
  void read_variables(const tinyxml2::XMLElement& list);

 private:
  int attribute_line(const tinyxml2::XMLElement& e, const char* name) const;
  std::optional<TypeDefinition> read_type_definition(const tinyxml2::XMLElement& e);
  void read_enumeration_items(const tinyxml2::XMLElement& e, TypeDefinition& type);
  void read_fmi2_variable(const tinyxml2::XMLElement& e);
  void read_fmi3_variable(const tinyxml2::XMLElement& e, VariableType type);
  bool read_common(const tinyxml2::XMLElement& e, Variable& v);
  void read_type_attributes(const tinyxml2::XMLElement& e, Variable& v);
  void read_fmi3_children(const tinyxml2::XMLElement& e, Variable& v);
  void add_variable(Variable v, int name_line);
  void check_value_reference(const Variable& v);

  FmuDescription& out_;
  std::vector<DescriptionProblem> problems_;
  std::size_t suppressed_ = 0;
  std::map<std::string, int> variable_lines_;  // names, also aliases -> line
  // Value references: FMI 3.0 one space; FMI 2.0 one per fmi2Get function (real, integer, boolean, string).
  std::map<std::pair<int, std::uint32_t>, std::size_t> references_;  // -> index into out_.variables
};

}  // namespace cosmic::fmi::detail

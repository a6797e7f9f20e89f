// An FMU's modelDescription.xml as the configuration and the runner read it
// (cosmic::fmi::parse_model_description): any bytes end in a description or in problems with lines
// inside the text, never a crash. An accepted description has a co-simulation interface, unique
// variable names, at most kMaxVariables variables, aliases that name an earlier variable, and the
// mapping table and parameter check answer for each of its variables without failing.
#include <set>
#include <string>
#include <string_view>

#include "cosmic/fmi_description.hpp"
#include "cosmic/fmi_mapping.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

int line_count(std::string_view text) {
  int lines = 1;
  for (const char c : text) lines += c == '\n' ? 1 : 0;
  return lines;
}

void check_accepted(const cosmic::fmi::FmuDescription& d) {
  require(d.co_simulation.has_value() && !d.co_simulation->model_identifier.empty());
  require(d.variables.size() <= cosmic::fmi::kMaxVariables);
  std::set<std::string> names;
  cosmic::TypeField number{"f", {}, {}, {}, {}, {}};
  number.type.scalar = cosmic::ScalarKind::int16;
  for (const auto& v : d.variables) {
    require(names.insert(v.name).second && !v.name.empty());
    if (!v.alias_of.empty()) require(names.count(v.alias_of) == 1);
    if (v.min && v.max) require(*v.min <= *v.max);
    (void)cosmic::fmi::mapping_problem(v, d, number, cosmic::fmi::Flow::input);
    (void)cosmic::fmi::mapping_problem(v, d, number, cosmic::fmi::Flow::output);
    (void)cosmic::fmi::parameter_problem(v, d, v.start.empty() ? "1" : v.start.front());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const cosmic::fmi::DescriptionResult r = cosmic::fmi::parse_model_description(text);
  require(r.problems.size() <= cosmic::fmi::kMaxReportedProblems + 1);
  const int lines = line_count(text);
  for (const auto& p : r.problems) require(p.line >= 0 && p.line <= lines && !p.message.empty());
  if (r.ok()) check_accepted(r.description);
  return 0;
}

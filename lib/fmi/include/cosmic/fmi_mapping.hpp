// Which FMU variables may carry which fields of a typed channel (docs/fmu.md, "The mapping table"),
// and which texts a parameter takes. The configuration checks a `fmus:` entry with these; the
// runner converts by the same table.
//
// Threads: pure functions; any thread.
#pragma once

#include <string>
#include <string_view>

#include "cosmic/channel_type.hpp"
#include "cosmic/fmi_description.hpp"
#include "cosmic/fmi_values.hpp"

namespace cosmic::fmi {

enum class Flow : std::uint8_t {
  input,   // a channel's field -> the FMU's input variable (before each step)
  output,  // the FMU's output variable -> a channel's field (after each step)
};

// Why `variable` cannot carry `field`'s values in `flow`; empty when it can:
//   float variable   <-> float32, float64 and integer fields (to an integer field rounded to nearest)
//   integer variable <-> integer fields whose range holds every value that may flow (the declared
//                        min/max where given, else the type's); -> float32, float64 fields
//   Boolean          <-> bool
//   Enumeration      <-> an enumeration field whose values hold every value that may flow, or an
//                        integer field whose range does
//   String           <-> string
// Binary, Clock and array variables, and array, sequence and record fields, are not mapped.
std::string mapping_problem(const Variable& variable, const FmuDescription& description, const TypeField& field,
                            Flow flow);

// Whether the YAML scalar `text` is a value `variable` takes at instantiation: a number (float), a whole
// number within its range (integer), true/false (Boolean), an item's name or value (Enumeration),
// any text (String). Empty, or why not.
std::string parameter_problem(const Variable& variable, const FmuDescription& description, std::string_view text);

}  // namespace cosmic::fmi

// The JSON Schema (draft 2020-12) of a typed channel's events as cosmic::JsonRepresentation writes
// them (issue 37): cosmicd records typed channels into MCAP as `json` messages with a `jsonschema`
// schema (recording.typed_encoding: json, or a type without a CDR form), so Foxglove and other
// MCAP readers show named, decoded fields.
//
// The schema holds for every text JsonRepresentation writes for the type, and is otherwise as tight
// as the type allows:
//   record       {"type": "object", "properties" in field order, "required": the fields without
//                present_when, "additionalProperties": false}; each conditional field adds an
//                if/then/else to "allOf": present exactly while its selector holds the value
//                (a selector value of 2^53 or more leaves the field merely optional: validators
//                that read numbers as doubles cannot tell it from its neighbours)
//   bool         {"type": "boolean"}
//   intN, uintN  {"type": "integer"} within the kind's limits
//   float32/64   {"type": ["number", "null"]} (NaN and infinities are written as null); float32
//                within its finite limits
//   enumeration  {"anyOf": [{"type": "string", "enum": its names}, an integer within its underlying
//                kind other than a named value]} (a value it does not name is written as the number)
//   string       {"type": "string", "maxLength": the byte bound}
//   array        {"type": "array", "items", "minItems" = "maxItems" = its length}
//   sequence     {"type": "array", "items", "maxItems": its bound}
// A field's description says its unit ("unit: m/s"), its declared range and, for a conditional
// field, which selector value carries it. The schema's title is the channel's name.
//
// A declared range (min, max) is only said in the description, never a "minimum" or "maximum": the
// gateway does not enforce it (check_compact accepts any value of the kind; decode never checks
// ranges, docs/components.md), so an event beyond it is forwarded, written and recorded, and a
// schema that refused it would be wrong about the recording it describes.
//
// Built with nlohmann-json (its ordered_json keeps the properties in field order and escapes every
// string). cosmic_core links it PRIVATE: it is header-only, so no library enters any link, it is
// neither I/O nor a network library (what cosmic_core stays free of), and no nlohmann type appears
// in this header. Text that is not valid UTF-8 (a DBC file's Latin-1 unit, a title) comes out with
// U+FFFD in place of each invalid byte, so json_schema() never throws but for memory.
//
// Pure, no I/O; any thread. Called once per channel when a recording starts, not per event.
#pragma once

#include <string>
#include <string_view>

#include "cosmic/channel_type.hpp"

namespace cosmic {

inline constexpr std::string_view kJsonSchemaDialect = "https://json-schema.org/draft/2020-12/schema";

// The schema as compact JSON text (one line).
std::string json_schema(const ChannelType& type, std::string_view title);

}  // namespace cosmic

// A typed channel's contents from a DBC message (issue 35; `type: {dbc: FILE, message: NAME}`):
// one field per signal, named as the signal, of the signal's physical type, with its unit and
// declared range, the multiplexor switch first and the others in the message's order; a value table
// (VAL_) makes an enumeration of the raw values; a multiplexed signal is present only while the
// switch selects it. Pure: no I/O; any thread.
//
// A signal's field type:
//   - an IEEE float signal: float32 when it is unscaled (factor 1, offset 0), else float64;
//   - with VAL_ names: an enumeration of the raw values (scaling does not apply), its integer the
//     smallest that holds the raw range and every named value;
//   - one unsigned bit, unscaled, declaring no range beyond 0..1: bool;
//   - a whole factor and offset: the smallest integer that holds every physical value the raw bits
//     give and the declared range (unsigned where none is negative);
//   - otherwise float64.
// VAL_ descriptions become identifiers (dbc_value_identifier). Refused: two signals the same frame
// carries (not multiplexed by different switch values) that share a bit.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/dbc.hpp"

namespace cosmic {

struct DbcChannelType {
  ChannelType type;
  std::vector<DbcError> errors;  // located at the signal (or the message) they concern
  bool ok() const { return errors.empty(); }
};

DbcChannelType channel_type_from_dbc(const DbcMessage& message);

// The type of the signal's field (above); the unit, range and presence belong to the TypeField.
FieldType dbc_field_type(const DbcSignal& signal);

// A VAL_ description as an enumeration value name: characters outside [A-Za-z0-9_] become '_'
// (runs of them one), leading and trailing '_' go, a name that would not start with a letter gets
// a 'v' in front, and an empty one is "v<value>" ("Not available" -> Not_available, "0x1F" ->
// v0x1F, "-" at 3 -> v3).
std::string dbc_value_identifier(std::string_view description, std::int64_t value);

}  // namespace cosmic

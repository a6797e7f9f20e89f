// Typed events as JSON (cosmic::JsonRepresentation, cosmic/json_representation.hpp): a type made
// from the input (scalars, enumerations, strings, arrays, sequences, nested records, conditional
// fields) and an event of the input's bytes. An event check_compact() refuses is refused by write();
// one it accepts is written within max_size() as a JSON object that nlohmann-json parses, with only
// the type's field names; a buffer one byte short of that refuses it, never written past.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/compact_layout.hpp"
#include "cosmic/json_representation.hpp"
#include "fuzz_input.hpp"
#include "fuzz_types.hpp"

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

// An enumeration's integer: odd bytes int8, even uint16.
constexpr cosmic::ScalarKind kEnumKinds[] = {cosmic::ScalarKind::uint16, cosmic::ScalarKind::int8};
constexpr cosmic::fuzz::TypeShapes kShapes{kEnumKinds, true};

bool names_are_the_types(const nlohmann::json& value, const std::vector<cosmic::TypeField>& fields) {
  if (!value.is_object()) return false;
  for (const auto& item : value.items()) {
    const std::string name = item.key();
    const auto f = std::find_if(fields.begin(), fields.end(), [&](const auto& field) { return field.name == name; });
    if (f == fields.end()) return false;
    if (f->type.kind == cosmic::FieldType::Kind::record && !names_are_the_types(item.value(), f->type.fields))
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  cosmic::ChannelType type;
  type.fields = cosmic::fuzz::make_fields(in, 0, kShapes);
  if (!cosmic::check_type(type).empty()) return 0;
  const auto bytes = in.bytes(cosmic::max_compact_size(type) + 8);
  const cosmic::JsonRepresentation json{cosmic::ChannelType(type)};
  std::string out(json.max_size(), '\0');
  const auto written = json.write(bytes, std::span<char>(out.data(), out.size()));
  const bool accepted = cosmic::check_compact(type, bytes).ok();
  require(written.has_value() == accepted);
  if (!accepted) return 0;
  require(*written <= json.max_size());
  const nlohmann::json parsed = nlohmann::json::parse(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(*written),
                                                      nullptr, /*allow_exceptions=*/false);
  require(!parsed.is_discarded() && names_are_the_types(parsed, type.fields));
  std::vector<char> short_buffer(*written - 1);
  require(!json.write(bytes, short_buffer).has_value());
  return 0;
}

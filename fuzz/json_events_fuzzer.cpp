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

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

cosmic::FieldType make_type(FuzzInput& in, int depth);

std::vector<cosmic::TypeField> make_fields(FuzzInput& in, int depth) {
  std::vector<cosmic::TypeField> fields;
  const int count = 1 + in.byte() % 5;
  for (int i = 0; i < count; ++i) {
    cosmic::TypeField f;
    f.name = "f" + std::to_string(i);
    f.type = make_type(in, depth + 1);
    // A conditional field on the first field when that is an integer.
    const auto& first = fields.empty() ? f.type : fields.front().type;
    const bool integral =
        (first.kind == cosmic::FieldType::Kind::scalar || first.kind == cosmic::FieldType::Kind::enumeration) &&
        cosmic::is_integer(first.scalar);
    if (i > 0 && integral && (in.byte() & 3) == 0) f.present_when = cosmic::FieldPresence{"f0", in.byte() % 3};
    fields.push_back(std::move(f));
  }
  return fields;
}

cosmic::FieldType make_type(FuzzInput& in, int depth) {
  cosmic::FieldType t;
  const std::uint8_t kind = depth >= 3 ? in.byte() % 2 : in.byte() % 6;
  t.scalar = static_cast<cosmic::ScalarKind>(in.byte() % 11);
  switch (kind) {
    case 0:
      t.kind = cosmic::FieldType::Kind::scalar;
      break;
    case 1:
      t.kind = cosmic::FieldType::Kind::enumeration;
      t.scalar = (in.byte() & 1) != 0 ? cosmic::ScalarKind::int8 : cosmic::ScalarKind::uint16;
      t.values = {{"A", 0}, {"B", 1 + in.byte() % 3}};
      break;
    case 2:
      t.kind = cosmic::FieldType::Kind::string;
      t.bound = 1 + in.byte() % 16;
      break;
    case 3:
    case 4:
      t.kind = kind == 3 ? cosmic::FieldType::Kind::array : cosmic::FieldType::Kind::sequence;
      t.bound = 1 + in.byte() % 4;
      t.element = {make_type(in, depth + 1)};
      break;
    default:
      t.kind = cosmic::FieldType::Kind::record;
      t.fields = make_fields(in, depth);
      break;
  }
  return t;
}

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
  type.fields = make_fields(in, 0);
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

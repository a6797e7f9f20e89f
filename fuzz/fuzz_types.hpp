// A typed channel's type made from fuzz input, shared by the fuzz targets of the representations
// (json_events_fuzzer.cpp, cdr_fuzzer.cpp): 1 to 5 fields a record, each a scalar, an enumeration,
// a bounded string, an array or a sequence of up to 4 elements, or a nested record (depth 3 at
// most), optionally fields present only while the first field holds a value.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "fuzz_input.hpp"

namespace cosmic::fuzz {

struct TypeShapes {
  std::span<const ScalarKind> enum_kinds;  // what an enumeration's integer may be
  bool conditional = false;                // fields present only while the first field holds a value
};

inline FieldType make_field_type(FuzzInput& in, int depth, const TypeShapes& shapes);

inline std::vector<TypeField> make_fields(FuzzInput& in, int depth, const TypeShapes& shapes) {
  std::vector<TypeField> fields;
  const int count = 1 + in.byte() % 5;
  for (int i = 0; i < count; ++i) {
    TypeField f;
    f.name = "f" + std::to_string(i);
    f.type = make_field_type(in, depth + 1, shapes);
    // A conditional field on the first field when that is an integer.
    const auto& first = fields.empty() ? f.type : fields.front().type;
    const bool integral = (first.kind == FieldType::Kind::scalar || first.kind == FieldType::Kind::enumeration) &&
                          is_integer(first.scalar);
    if (shapes.conditional && i > 0 && integral && (in.byte() & 3) == 0)
      f.present_when = FieldPresence{"f0", in.byte() % 3};
    fields.push_back(std::move(f));
  }
  return fields;
}

inline FieldType make_field_type(FuzzInput& in, int depth, const TypeShapes& shapes) {
  FieldType t;
  const std::uint8_t kind = depth >= 3 ? in.byte() % 2 : in.byte() % 6;
  t.scalar = static_cast<ScalarKind>(in.byte() % 11);
  switch (kind) {
    case 0:
      t.kind = FieldType::Kind::scalar;
      break;
    case 1:
      t.kind = FieldType::Kind::enumeration;
      t.scalar = shapes.enum_kinds[in.byte() % shapes.enum_kinds.size()];
      t.values = {{"A", 0}, {"B", 1 + in.byte() % 3}};
      break;
    case 2:
      t.kind = FieldType::Kind::string;
      t.bound = 1 + in.byte() % 16;
      break;
    case 3:
    case 4:
      t.kind = kind == 3 ? FieldType::Kind::array : FieldType::Kind::sequence;
      t.bound = 1 + in.byte() % 4;
      t.element = {make_field_type(in, depth + 1, shapes)};
      break;
    default:
      t.kind = FieldType::Kind::record;
      t.fields = make_fields(in, depth, shapes);
      break;
  }
  return t;
}

}  // namespace cosmic::fuzz

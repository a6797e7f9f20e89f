// A typed channel's LCM messages in the struct's own encoding (cosmic::LcmRepresentation,
// cosmic/lcm_representation.hpp): an LCM type file written from the input's first bytes (up to three
// structs, the later ones nesting the earlier; every primitive, strings, fixed and variable
// dimensions up to two deep), read by parse_lcm_types, its last struct's type from lcm_channel_type
// with small bounds; then the rest of the input as a message (after the struct's fingerprint, or
// as it is) and as an event. The representation is made exactly when the type is sound. A message
// to_compact() accepts is an event check_compact() accepts that from_compact() writes back to the
// same bytes (a boolean's nonzero byte as 1), and that event comes back again; a refused one is
// malformed. An event check_compact() accepts is refused as malformed (its sequences' counts are not
// their count members') or written as a message that reads back to the very event. Buffers one byte
// under the bounds are too small.
#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/lcm_representation.hpp"
#include "cosmic/lcm_types.hpp"
#include "fuzz_input.hpp"

using cosmic::ConversionFault;
using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr const char* kPrimitives[] = {"int8_t", "int16_t", "int32_t", "int64_t", "float",
                                       "double", "boolean", "byte",    "string"};
constexpr std::size_t kPrimitiveCount = sizeof kPrimitives / sizeof kPrimitives[0];
constexpr std::uint32_t kStringBound = 8;    // bytes of any string
constexpr std::uint32_t kNestedBound = 3;    // elements of a nested struct's sequence
constexpr std::uint32_t kTopLevelBound = 4;  // elements of the struct's own sequences (max_length)

struct LcmFuzzText {
  std::string text;
  bool booleans = false;
};

// One member: its type (a primitive or an earlier struct) and up to two dimensions, a variable one
// sized by an earlier integer member without dimensions.
std::string lcm_fuzz_member(FuzzInput& in, std::size_t index, std::size_t earlier_structs,
                            std::vector<std::string>& counts, bool& booleans) {
  const std::uint8_t choice = in.byte();
  const std::size_t kinds = kPrimitiveCount + (earlier_structs > 0 ? 1 : 0);
  const std::size_t kind = choice % kinds;
  const std::string type =
      kind < kPrimitiveCount ? kPrimitives[kind] : "fz.s" + std::to_string((choice / kinds) % earlier_structs) + "_t";
  booleans = booleans || type == "boolean";
  const std::string name = "m" + std::to_string(index);
  std::string member = "  " + type + " " + name;
  const std::size_t dimensions = in.byte() % 3;
  for (std::size_t d = 0; d < dimensions; ++d) {
    const std::uint8_t size = in.byte();
    if ((size & 1) != 0 && !counts.empty()) {
      member += "[" + counts[(size >> 1) % counts.size()] + "]";
    } else {
      member += "[" + std::to_string(1 + (size >> 1) % 3) + "]";
    }
  }
  if (dimensions == 0 && kind < 4) counts.push_back(name);  // an integer without dimensions
  return member + ";\n";
}

LcmFuzzText lcm_fuzz_text(FuzzInput& in) {
  LcmFuzzText out{"package fz;\n", false};
  const std::size_t structs = 1 + in.byte() % 3;
  for (std::size_t s = 0; s < structs; ++s) {
    out.text += "struct s" + std::to_string(s) + "_t {\n";
    std::vector<std::string> counts;
    const std::size_t members = 1 + in.byte() % 6;
    for (std::size_t m = 0; m < members; ++m) out.text += lcm_fuzz_member(in, m, s, counts, out.booleans);
    out.text += "}\n";
  }
  return out;
}

// Small bounds keep every buffer small: strings and nested structs' sequences.
void lcm_fuzz_tighten(cosmic::FieldType& type) {
  if (type.kind == cosmic::FieldType::Kind::string) type.bound = std::min(type.bound, kStringBound);
  if (type.kind == cosmic::FieldType::Kind::sequence) type.bound = std::min(type.bound, kNestedBound);
  for (cosmic::FieldType& element : type.element) lcm_fuzz_tighten(element);
  for (cosmic::TypeField& f : type.fields) lcm_fuzz_tighten(f.type);
}

Bytes lcm_fuzz_fingerprinted(std::uint64_t fingerprint, std::span<const std::uint8_t> body) {
  Bytes out;
  for (int shift = 56; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(fingerprint >> shift));
  out.insert(out.end(), body.begin(), body.end());
  return out;
}

// The message's way through the event and back.
void lcm_fuzz_message(const cosmic::LcmRepresentation& lcm, const cosmic::ChannelType& type, const Bytes& wire,
                      bool booleans) {
  Bytes event(lcm.max_compact_size());
  const cosmic::Conversion read = lcm.to_compact(wire, event);
  if (!read.ok()) {
    require(read.fault == ConversionFault::malformed && read.size == 0);
    return;
  }
  event.resize(read.size);
  require(cosmic::check_compact(type, event).ok());
  Bytes written(lcm.max_wire_size());
  const cosmic::Conversion write = lcm.from_compact(event, written);
  require(write.ok() && write.size == wire.size());
  written.resize(write.size);
  for (std::size_t i = 0; i < wire.size(); ++i) {
    // Only a boolean's nonzero byte may change, to 1: the generated type has booleans then.
    require(written[i] == wire[i] || (booleans && wire[i] > 1 && written[i] == 1));
  }
  Bytes again(lcm.max_compact_size());
  const cosmic::Conversion reread = lcm.to_compact(written, again);
  require(reread.ok() && Bytes(again.begin(), again.begin() + static_cast<std::ptrdiff_t>(reread.size)) == event);
  if (lcm.max_compact_size() > 0) {
    Bytes short_event(lcm.max_compact_size() - 1);
    require(lcm.to_compact(wire, short_event).fault == ConversionFault::too_small);
  }
  Bytes short_wire(lcm.max_wire_size() - 1);
  require(lcm.from_compact(event, short_wire).fault == ConversionFault::too_small);
}

// The event's way through a message and back.
void lcm_fuzz_event(const cosmic::LcmRepresentation& lcm, const cosmic::ChannelType& type,
                    std::span<const std::uint8_t> event) {
  Bytes wire(lcm.max_wire_size());
  const cosmic::Conversion write = lcm.from_compact(event, wire);
  if (!cosmic::check_compact(type, event).ok()) return;  // no promise: only that nothing breaks
  if (!write.ok()) {
    require(write.fault == ConversionFault::malformed && write.size == 0);
    return;
  }
  wire.resize(write.size);
  Bytes back(lcm.max_compact_size());
  const cosmic::Conversion read = lcm.to_compact(wire, back);
  require(read.ok() && read.size == event.size());
  require(std::equal(event.begin(), event.end(), back.begin()));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  const LcmFuzzText text = lcm_fuzz_text(in);
  const cosmic::LcmTypeFile file = cosmic::parse_lcm_types(text.text);
  require(file.ok());
  const cosmic::LcmStruct& top = file.structs.back();
  std::map<std::string, std::uint32_t> max_length;
  for (const cosmic::LcmMember& m : top.members) {
    for (const cosmic::LcmDimension& d : m.dimensions) {
      if (d.variable) max_length[m.name] = 1 + in.byte() % kTopLevelBound;
    }
  }
  cosmic::LcmChannelType typed = cosmic::lcm_channel_type(file, top, max_length);
  // Its only possible errors are of size (nested sequences at their counts' limits, strings at
  // 65536 bytes), which tightening may mend: whether the type is sound is check_type's to say.
  for (cosmic::TypeField& f : typed.type.fields) lcm_fuzz_tighten(f.type);
  const auto made = cosmic::LcmRepresentation::make(file, top, typed.type);
  require(made.ok() == cosmic::check_type(typed.type).empty());
  if (!made.ok()) return 0;
  const cosmic::LcmRepresentation& lcm = made.value();
  require(lcm.describe() == "LCM " + top.full_name());

  const bool fingerprinted = (in.byte() & 1) != 0;
  const auto rest = in.bytes(size);
  lcm_fuzz_message(lcm, typed.type,
                   fingerprinted ? lcm_fuzz_fingerprinted(lcm.fingerprint(), rest) : Bytes(rest.begin(), rest.end()),
                   text.booleans);
  lcm_fuzz_event(lcm, typed.type, rest);
  return 0;
}

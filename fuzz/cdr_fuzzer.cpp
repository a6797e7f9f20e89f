// A typed channel's samples in extended CDR (cosmic::CdrRepresentation, cosmic/cdr_representation.hpp):
// a type made from the input (scalars, enumerations of 8 to 64 bits, strings, arrays, sequences,
// nested records) and the rest of the input as a sample (encapsulation header first) or as an event
// in the compact layout. A sample to_compact() accepts is an event check_compact() accepts that,
// written back in the sample's own version and extensibility, reads back the same. An event
// from_compact() accepts is exactly one check_compact() accepts; it is written in XCDR1, XCDR2 and
// XCDR2 appendable within max_wire_size() (a multiple of 4) and read back the same; a buffer one
// byte short of max_wire_size() is refused as too_small, never written past.
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/cdr_representation.hpp"
#include "cosmic/compact_layout.hpp"
#include "fuzz_input.hpp"
#include "fuzz_types.hpp"

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr cosmic::ScalarKind kEnumKinds[] = {cosmic::ScalarKind::int8, cosmic::ScalarKind::uint16,
                                             cosmic::ScalarKind::int32, cosmic::ScalarKind::uint32,
                                             cosmic::ScalarKind::int64};

constexpr cosmic::fuzz::TypeShapes kShapes{kEnumKinds, false};

std::span<const std::uint8_t> first(const Bytes& bytes, std::size_t size) {
  return std::span<const std::uint8_t>(bytes).first(size);
}

// The event as a sample of `cdr` and back; a buffer one byte short refused.
void require_round_trip(const cosmic::CdrRepresentation& cdr, std::span<const std::uint8_t> event) {
  Bytes wire(cdr.max_wire_size());
  const cosmic::Conversion written = cdr.from_compact(event, wire);
  require(written.ok() && written.size <= wire.size() && written.size % 4 == 0);
  Bytes back(cdr.max_compact_size());
  const cosmic::Conversion read = cdr.to_compact(first(wire, written.size), back);
  require(read.ok() && std::equal(event.begin(), event.end(), back.begin(), back.begin() + read.size) &&
          read.size == event.size());
  Bytes short_wire(cdr.max_wire_size() - 1);  // on the heap, exactly: ASan sees a write past it
  const cosmic::Conversion refused = cdr.from_compact(event, short_wire);
  require(refused.ok() ? refused.size <= short_wire.size() : refused.fault == cosmic::ConversionFault::too_small);
}

// The representation that writes a sample the way `wire` is (its encapsulation identifier).
const cosmic::CdrRepresentation& writer_like(std::span<const std::uint8_t> wire,
                                             const std::vector<cosmic::CdrRepresentation>& all) {
  switch (wire[1] & ~1u) {
    case 0x06:
      return all[1];
    case 0x08:
      return all[2];
    default:
      return all[0];
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  cosmic::ChannelType type;
  type.fields = cosmic::fuzz::make_fields(in, 0, kShapes);
  if (!cosmic::check_type(type).empty()) return 0;
  std::vector<cosmic::CdrRepresentation> all;
  for (const auto& [version, extensibility] :
       {std::pair{cosmic::DdsRepresentation::xcdr1, cosmic::CdrExtensibility::final_type},
        std::pair{cosmic::DdsRepresentation::xcdr2, cosmic::CdrExtensibility::final_type},
        std::pair{cosmic::DdsRepresentation::xcdr2, cosmic::CdrExtensibility::appendable}}) {
    auto made = cosmic::CdrRepresentation::make(type, version, extensibility);
    require(made.ok());
    all.push_back(std::move(made).value());
  }
  const bool as_event = (in.byte() & 1) != 0;
  const auto rest = in.bytes(all[2].max_wire_size() + 16);
  if (as_event) {
    const bool accepted = cosmic::check_compact(type, rest).ok();
    for (const cosmic::CdrRepresentation& cdr : all) {
      Bytes wire(cdr.max_wire_size());
      require(cdr.from_compact(rest, wire).ok() == accepted);
      if (accepted) require_round_trip(cdr, rest);
    }
    return 0;
  }
  Bytes event(all[0].max_compact_size());
  const cosmic::Conversion read = all[0].to_compact(rest, event);
  // Whichever representation reads, the result is the same: the sample says its encoding.
  for (std::size_t i = 1; i < all.size(); ++i) {
    Bytes again(all[i].max_compact_size());
    const cosmic::Conversion c = all[i].to_compact(rest, again);
    require(c.fault == read.fault && c.size == read.size &&
            std::equal(again.begin(), again.begin() + c.size, event.begin()));
  }
  if (!read.ok()) return 0;
  require(read.size <= event.size());
  const auto accepted = first(event, read.size);
  require(cosmic::check_compact(type, accepted).ok());
  require_round_trip(writer_like(rest, all), accepted);
  for (const cosmic::CdrRepresentation& cdr : all) require_round_trip(cdr, accepted);
  return 0;
}

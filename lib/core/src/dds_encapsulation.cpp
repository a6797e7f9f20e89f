#include "cosmic/dds_encapsulation.hpp"

#include <array>

namespace cosmic {
namespace {

struct KnownId {
  std::uint16_t id;
  DdsRepresentation representation;
  const char* name;
};

// XCDR1: plain and parameter-list CDR; XCDR2: plain, delimited and parameter-list CDR2. The
// low bit of every identifier is the byte order (1: little-endian).
constexpr std::array<KnownId, 10> kKnown{{
    {0x0000, DdsRepresentation::xcdr1, "CDR_BE"},
    {0x0001, DdsRepresentation::xcdr1, "CDR_LE"},
    {0x0002, DdsRepresentation::xcdr1, "PL_CDR_BE"},
    {0x0003, DdsRepresentation::xcdr1, "PL_CDR_LE"},
    {0x0006, DdsRepresentation::xcdr2, "CDR2_BE"},
    {0x0007, DdsRepresentation::xcdr2, "CDR2_LE"},
    {0x0008, DdsRepresentation::xcdr2, "D_CDR2_BE"},
    {0x0009, DdsRepresentation::xcdr2, "D_CDR2_LE"},
    {0x000a, DdsRepresentation::xcdr2, "PL_CDR2_BE"},
    {0x000b, DdsRepresentation::xcdr2, "PL_CDR2_LE"},
}};

}  // namespace

std::optional<DdsEncapsulation> read_dds_encapsulation(std::span<const std::uint8_t> sample) {
  if (sample.size() < kDdsEncapsulationBytes) return std::nullopt;
  const auto id = static_cast<std::uint16_t>((sample[0] << 8) | sample[1]);
  for (const KnownId& known : kKnown) {
    if (known.id == id) return DdsEncapsulation{id, known.representation, (id & 1) != 0, known.name};
  }
  return std::nullopt;
}

}  // namespace cosmic

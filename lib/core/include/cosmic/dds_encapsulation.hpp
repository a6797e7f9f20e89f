// The encapsulation header that starts every serialized DDS sample (RTPS 2.5 section 10.2,
// DDS-XTypes 1.3 section 7.6.3.1.2): 2 bytes representation identifier (big-endian), 2 bytes
// options. A native DDS channel carries samples as these bytes (header included); this unit says
// which extended CDR version a sample's header names, so a writer only ever sends what it
// announced. Pure function, fuzzed (fuzz/dds_encapsulation_fuzzer.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "cosmic/model.hpp"

namespace cosmic {

inline constexpr std::size_t kDdsEncapsulationBytes = 4;

struct DdsEncapsulation {
  std::uint16_t id = 0;  // e.g. 0x0001 CDR_LE, 0x0007 CDR2_LE
  DdsRepresentation representation = DdsRepresentation::xcdr1;
  bool little_endian = true;
  const char* name = "";  // "CDR_LE", "PL_CDR2_BE", ...
};

// The header of `sample`, or nullopt when it is shorter than a header or names no CDR
// representation (XML, vendor ids and unassigned values).
std::optional<DdsEncapsulation> read_dds_encapsulation(std::span<const std::uint8_t> sample);

}  // namespace cosmic

// A native DDS topic's sample as Fast DDS hands it to the opaque type (the serialized payload of
// any type, header included), then the check a native writer makes before sending bytes: the
// encapsulation header. The bytes must come back out of serialize() unchanged, and a header the
// reader names must be one of the CDR identifiers with its byte order in the low bit.
#include <cstdint>
#include <cstring>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "cosmic/dds_encapsulation.hpp"
#include "dds_opaque_type.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static cosmic::dds_detail::OpaqueType type("fuzz::Any_");
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  cosmic::dds_detail::OpaqueSample sample;
  require(type.deserialize(&payload, &sample));
  require(sample.bytes.size() == size);
  if (const auto header = cosmic::read_dds_encapsulation(sample.bytes)) {
    require(size >= cosmic::kDdsEncapsulationBytes);
    require(header->id <= 0x000b && header->id != 0x0004 && header->id != 0x0005);
    require(header->little_endian == ((data[1] & 1) != 0));
  }
  const std::uint32_t needed = type.getSerializedSizeProvider(&sample)();
  require(needed == size);
  eprosima::fastrtps::rtps::SerializedPayload_t out(needed);
  require(type.serialize(&sample, &out));
  require(out.length == size && (size == 0 || std::memcmp(out.data, data, size) == 0));
  return 0;
}

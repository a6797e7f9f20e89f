// A DDS sample as Fast DDS hands it to the envelope type: the serialized payload (encapsulation
// header + CDR) deserialized by the generated EnvelopePubSubType, as on every received sample.
// A decoded envelope must serialize again within the size the type reports for it.
#include <cstdint>
#include <cstring>

#include <fastcdr/exceptions/Exception.h>

#include "cosmic_dds_idl/EnvelopePubSubTypes.h"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static cosmic::EnvelopePubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  cosmic::Envelope envelope;
  // The generated code turns a short buffer into `false` but lets Fast CDR's BadParamException
  // (an unknown encapsulation kind) escape; the adapter catches every exception around
  // take_next_sample (dds_adapter.cpp) and counts a receive error, and so does this target.
  try {
    if (!type.deserialize(&payload, &envelope)) return 0;
  } catch (const eprosima::fastcdr::exception::Exception&) {
    return 0;
  }
  const std::uint32_t needed = type.getSerializedSizeProvider(&envelope)();
  eprosima::fastrtps::rtps::SerializedPayload_t out(needed);
  require(type.serialize(&envelope, &out));
  require(out.length <= needed);
  return 0;
}

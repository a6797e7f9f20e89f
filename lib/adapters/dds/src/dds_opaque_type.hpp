// The type of native DDS topics: any DDS type, carried as its serialized payload (encapsulation
// header included) without knowing its members, the way DDS-Pipe's generic type forwards topics.
// Internal to the DDS adapter; fuzzed alone (fuzz/dds_opaque_fuzzer.cpp).
//
// Ownership and threads: a participant owns its registered OpaqueType (through TypeSupport);
// Fast DDS calls serialize() on the writing thread (an egress lane, or a receive thread in its place) and deserialize()
// on the reader's take() (a Fast DDS receive thread), each on the caller's own sample.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace cosmic::dds_detail {

// One serialized sample: the encapsulation header (4 bytes) and the CDR body, as on the wire.
struct OpaqueSample {
  std::vector<std::uint8_t> bytes;
};

class OpaqueType final : public eprosima::fastdds::dds::TopicDataType {
 public:
  // Samples initially get this many bytes of history memory; bigger ones are reallocated
  // (PREALLOCATED_WITH_REALLOC), so a small type never reserves the segment's largest message.
  static constexpr std::uint32_t kInitialSampleBytes = 512;

  // `type_name`: the name announced in discovery (e.g. geometry_msgs::msg::dds_::Twist_).
  explicit OpaqueType(const std::string& type_name);

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override;
  void* createData() override;
  void deleteData(void* data) override;
  // Keyless: a keyed type's instance key cannot be computed from bytes whose layout is unknown
  // (the configuration refuses `keyed: true`; docs/dds-mapping.md).
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5) override;
};

}  // namespace cosmic::dds_detail

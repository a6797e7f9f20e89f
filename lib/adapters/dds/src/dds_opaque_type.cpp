#include "dds_opaque_type.hpp"

#include <cstring>
#include <limits>

#include <fastdds/rtps/common/SerializedPayload.h>

namespace cosmic::dds_detail {

namespace rtps = eprosima::fastrtps::rtps;

OpaqueType::OpaqueType(const std::string& type_name) {
  setName(type_name.c_str());
  m_typeSize = kInitialSampleBytes;
  m_isGetKeyDefined = false;
  // No TypeObject or TypeInformation: the members are unknown, and announcing an empty type
  // would make a peer that checks types refuse the match.
  auto_fill_type_object(false);
  auto_fill_type_information(false);
}

bool OpaqueType::serialize(void* data, rtps::SerializedPayload_t* payload) {
  const auto& bytes = static_cast<const OpaqueSample*>(data)->bytes;
  if (bytes.size() > std::numeric_limits<std::uint32_t>::max() || bytes.size() > payload->max_size) {
    return false;
  }
  if (!bytes.empty()) std::memcpy(payload->data, bytes.data(), bytes.size());
  payload->length = static_cast<std::uint32_t>(bytes.size());
  // Informational only (the header is part of the bytes): the byte order the header names.
  payload->encapsulation = bytes.size() >= 2 && (bytes[1] & 1) != 0 ? CDR_LE : CDR_BE;
  return true;
}

bool OpaqueType::deserialize(rtps::SerializedPayload_t* payload, void* data) {
  auto& bytes = static_cast<OpaqueSample*>(data)->bytes;
  if (payload->length > payload->max_size) return false;
  bytes.assign(payload->data, payload->data + payload->length);  // keeps the vector's capacity
  return true;
}

std::function<std::uint32_t()> OpaqueType::getSerializedSizeProvider(void* data) {
  const auto* sample = static_cast<const OpaqueSample*>(data);
  return [sample]() { return static_cast<std::uint32_t>(sample->bytes.size()); };
}

void* OpaqueType::createData() { return new OpaqueSample(); }

void OpaqueType::deleteData(void* data) { delete static_cast<OpaqueSample*>(data); }

bool OpaqueType::getKey(void*, rtps::InstanceHandle_t*, bool) { return false; }

}  // namespace cosmic::dds_detail

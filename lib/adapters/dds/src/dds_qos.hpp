// How a segment and a channel become Fast DDS QoS (internal to the DDS adapter).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "cosmic/dds_names.hpp"
#include "cosmic/model.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::dds_detail {

// Largest history depth of a channel endpoint.
inline constexpr std::int32_t kMaxHistoryDepth = 32;

// Longest time DataWriter::write() may block the calling egress lane (or the receive thread
// sending in its place) (every writer is reliable;
// with KEEP_LAST it only waits for the writer's own mutex and history, never for
// acknowledgements). On timeout send() answers queue_full instead of stalling every other
// channel of its class behind this one. 100 us is a fraction of the shortest latency bound a
// segment is configured with, and far above an uncontended write (a few microseconds).
inline constexpr std::int64_t kMaxBlockingNs = 100'000;

// Heartbeat period of reliable writers: reaction_time / 2 within these bounds.
inline constexpr std::int64_t kMinHeartbeatNs = 5'000'000;
inline constexpr std::int64_t kMaxHeartbeatNs = 100'000'000;

// NACK suppression of reliable writers (dds_qos.cpp says why): a fifth of the shortest heartbeat.
inline constexpr std::int64_t kNackSuppressionNs = 1'000'000;

// KEEP_LAST depth of a channel: max(1, omission_degree + 1), capped at kMaxHistoryDepth.
// A channel that tolerates `omission_degree` consecutive losses is served by keeping that many
// samples plus the newest one: a reliable writer can still repair a burst of that length, while
// anything older is superseded for a real-time channel (re-sending it would only delay newer
// events). The cap bounds the per-endpoint history memory (omission_degree is a 32-bit number
// from the configuration) and the repair traffic a single channel can cause.
std::int32_t history_depth(std::uint32_t omission_degree);

// The QoS-relevant shape of one endpoint: two bindings with equal shapes can share an endpoint.
struct EndpointShape {
  DdsTopicRef topic;  // topic, type and format (envelope or native)
  std::int32_t depth = 1;
  std::optional<Nanos> validity;
  std::optional<Nanos> reaction_time;
  bool operator==(const EndpointShape&) const = default;
};
EndpointShape shape_of(const SegmentSpec& segment, const ChannelSpec& channel);

// Writers offer the most (RELIABLE, TRANSIENT_LOCAL) and promise nothing a default reader does
// not request (no deadline, latency_budget 0); readers request the least (the segment's
// reliability, VOLATILE, no deadline). docs/dds-mapping.md lists every policy and why. A native
// topic's writer announces its representation (XCDR or XCDR2); its reader accepts both.
eprosima::fastdds::dds::DataWriterQos writer_qos(const SegmentSpec& segment, const ChannelSpec& channel);
eprosima::fastdds::dds::DataReaderQos reader_qos(const SegmentSpec& segment, const ChannelSpec& channel);

// Transports (interface allow-list; shared memory or UDP alone) and discovery (simple or
// discovery-server client) of one of the segment's participants. Without `shared_memory` the
// participant speaks UDPv4 only, to peers on this host too. Fails for an unknown interface or a
// malformed "IP:PORT".
Status participant_qos(const SegmentSpec& segment, const std::string& participant_name, bool shared_memory,
                       eprosima::fastdds::dds::DomainParticipantQos& qos);

// Largest DDS domain id whose RTPS ports fit in 16 bits with the default port parameters.
inline constexpr std::uint32_t kMaxDomainId = 232;

}  // namespace cosmic::dds_detail

// The DDS segment adapter (eProsima Fast DDS 2.9), behind cosmic::SegmentAdapter.
//
// Mapping (DESIGN.md section 6; docs/dds-mapping.md has every policy and the reasons):
// - One DomainParticipant per class of channel in use on the segment (domain id =
//   segment.dds.domain; the NRT one from start(), HRT and SRT with their first channel), each
//   with one Publisher and one Subscriber, so no lower class shares Fast DDS's per-participant
//   send lock or threads with a higher one. One topic per channel, named by dds_topic_of()
//   (cosmic/dds_names.hpp): an envelope channel's topic is "cosmic/<channel name>" with '-' and
//   '.' mapped to '_', of type "cosmic::Envelope" (lib/adapters/dds/idl/Envelope.idl, @final,
//   plain CDR); a native channel's is the topic and type it names, carried opaque (the serialized
//   sample as is, encapsulation header included; keyless). Two channels mapping to one topic are
//   refused by configure(). A channel bound with role subscriber (the gateway sends there) gets a
//   DataWriter; with role publisher (the gateway receives there) a DataReader.
// - Native topics: the writer announces the declared representation (XCDR or XCDR2) and send()
//   refuses (failed, logged once per writer) an event whose bytes do not start with an
//   encapsulation header of that version; the reader accepts both versions. A native sample
//   carries no origin or sequence: it arrives as a native source's event (origin 0, sequence =
//   its writer's RTPS sequence number).
// - QoS: a default reader and a default writer of any vendor match our endpoints.
//     writer  RELIABLE (max_blocking_time 100 us), TRANSIENT_LOCAL, KEEP_LAST depth
//             max(1, omission_degree + 1) capped at 32, latency_budget 0, no deadline,
//             lifespan = temp_validity (when set)
//     reader  reliability of the segment, VOLATILE, KEEP_LAST >= 256 (a buffer before take()),
//             latency_budget = reaction_time (accepts every writer offering less), no deadline
//   `period` (a minimum inter-arrival time) never becomes a deadline (a maximum gap). On a
//   reliable segment a best-effort native writer is refused by the DDS rule: that, and any
//   other refusal, is counted per channel (incompatible_peers()) and logged.
//   Reliable writers: heartbeat period reaction_time / 2 within [5 ms, 100 ms] (Fast DDS's 3 s
//   default would repair a lost last event seconds late). Synchronous publish mode.
// - send() contract (called by the segment's egress lanes, one per class, possibly at once):
//   never throws, never waits for acknowledgements, and returns within about 100 us plus the
//   time to hand one sample to the socket: a write that cannot get the writer's history in that
//   time answers SendStatus::queue_full (the router counts it); an unknown channel or an event
//   above segment.max_message_size answers failed. Channels of one class share a lane, so one
//   slow channel delays its class by at most that bound.
// - Inbound events: received_at is the sample's reception time (Fast DDS's realtime stamp moved
//   to the steady clock, never later than the callback), so residence counts from arrival. An
//   envelope with origin 0 (a native publisher) gets its writer's RTPS sample sequence number,
//   truncated to 32 bits, as header.sequence: losses on the hop from it stay visible.
// - Matching is asymmetric: a VOLATILE reader drops what a writer sent before the reader itself
//   matched that writer, even after the writer matched the reader. matched_endpoints() lets
//   tests and tools wait for our side.
// - Transports: without an allow-list, Fast DDS's builtin transports (UDPv4 + shared memory).
//   With segment.dds.interfaces (IPv4 addresses or interface names, resolved to their IPv4
//   address at start()), a UDPv4 transport restricted to those interfaces plus the shared
//   memory transport (host-local only, so it cannot leave the allowed networks).
//   segment.dds.discovery_server "IP:PORT": the participant is a discovery-server CLIENT of the
//   server with the default id 0 (`fastdds discovery -i 0 -l IP -p PORT`); otherwise simple
//   discovery (multicast SPDP).
// - The gateway never receives its own publications: Fast DDS 2.9 has no
//   "fastdds.ignore_local_endpoints" (it appeared in 2.10; the property is set anyway and takes
//   over after an upgrade), so samples written by this participant are dropped on reception by
//   GUID prefix and reported as InboundProblem::own_echo (expected, never counted as a loss). An
//   envelope from another participant that carries this gateway's origin (a loop through another
//   gateway, or a spoof) is delivered: the router's ingress check drops and counts it.
// - Envelopes whose payload exceeds segment.max_message_size are refused by send() (failed) and
//   dropped on reception (InboundProblem::decode_error).
// - statistics(): received = envelopes taken from DDS (own echoes and malformed ones included),
//   receive_errors = malformed ones and failed takes, sent = successful writes, send_errors =
//   refused sends (unknown channel, too large, write failed or timed out), overflow_drops =
//   samples Fast DDS reports lost (SAMPLE_LOST) on our readers.
// - Lifecycle: health() is down "not started" until start() succeeds, down with the reason when
//   it fails (bad interface, bad discovery server, domain > 232, participant creation failed),
//   up while running, down "stopped" after stop(). configure() before start() fails; a failing
//   configure() leaves the running configuration as it was. A binding whose spec changes
//   (topic or QoS) gets a new endpoint; events in flight on the old reader may be lost then.
//   stop() is idempotent (the destructor calls it); start() may follow it again.
// - Fast DDS logs through a process-wide singleton that prints to stdout; the first started
//   adapter replaces that output with the Loggers of the running adapters (warnings, errors).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/dds_names.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

// The DDS adapter with DDS-specific observations that tools and tests use to wait for discovery
// instead of sleeping. Not part of SegmentAdapter on purpose.
class DdsSegmentAdapter : public SegmentAdapter {
 public:
  // Remote endpoints currently matched with the channel's writer (role subscriber) or reader
  // (role publisher); 0 when the channel is not bound in that role.
  virtual std::size_t matched_endpoints(ChannelId channel, HopRole role) const = 0;
};

// Never throws for bad input: errors come back from start() and configure().
std::unique_ptr<DdsSegmentAdapter> make_dds_segment_adapter(const SegmentSpec& segment, const GatewayIdentity& self,
                                                            Logger& log);
std::unique_ptr<SegmentAdapter> make_dds_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log);

}  // namespace cosmic

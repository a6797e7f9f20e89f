// The one interface every transport implements (CAN, DDS, LCM, in-memory). It has no
// transport-specific methods: what a transport needs to know about a channel travels in
// ChannelBinding (the channel's spec plus admission's plan for this hop).
//
// Threads: start/configure/stop are called by the control thread, send() by the egress lane
// threads of this segment (one per class, so send() may run on up to three threads at once, each
// for channels of its own class; a lane may instead let a receive thread of its class make the
// send, never two senders of one class at once), health()/statistics() by any thread.
//
// send() contract: it returns within a bounded, short time (microseconds; a transport that can
// block, like a reliable DDS writer, is given a small blocking bound) and never waits on another
// segment or on a lower class's send for longer than one frame or message. What the transport
// cannot take now is refused with SendStatus::queue_full (the router counts it), not waited for. Inbound events go to
// the EventSink from threads the adapter owns, between start() and the return of stop().
//
// Lock discipline on the send path (every adapter): what send() needs is taken under a
// priority-inheriting mutex (the binding table as a SnapshotTable of the adapter kit: a pointer
// copy), the write happens outside it, and what it logs is written after. The only lock a send
// may hold across its write is one that no other class's send takes (DDS: the channel's writer;
// LCM: the class's socket; CAN: its io mutex decides, the frames leave after).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/event.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/model.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {

// One channel on this segment as admission planned it.
struct ChannelBinding {
  ChannelId id = kNoChannel;
  ChannelSpec spec;
  HopRole role = HopRole::publisher;  // publisher: the gateway receives it here; subscriber: sends it here
  std::optional<CanHopPlan> can;      // CAN segments only
  friend bool operator==(const ChannelBinding&, const ChannelBinding&) = default;
};

// Why an inbound message could not become an event.
// unauthenticated, replayed: a message of an authenticated hop (docs/security.md) whose tag is not
// valid, or that was sent before or outside the freshness window.
enum class InboundProblem { decode_error, unknown_channel, own_echo, unauthenticated, replayed };

// Implemented by the router, one per segment. Called from adapter threads; never blocks long:
// the router does its ingress work on the calling thread and hands the event to the egress
// lanes (one hand-off; or sends it on this thread, see InboundEvent::receiver_class), so the
// adapter should call it straight from the thread that read the network.
class EventSink {
 public:
  virtual void on_event(const InboundEvent& event) = 0;
  virtual void on_problem(ChannelId channel, InboundProblem problem) = 0;
  // Whether events of `channel` arriving here are routed now. A source that needs no matching to
  // be ready (a replay) waits for it before its first event, so that none is due while the
  // gateway's routes do not yet lead from this segment (a replacement's hop opened ahead of its
  // switch, a bind between its adapters' configuration and its routes). Any thread.
  virtual bool routes(ChannelId channel) const {
    static_cast<void>(channel);
    return true;
  }

  // How the adapter's receive threads should run (gateway.realtime): an adapter applies it, with
  // its own thread name, to every receive thread it owns, and logs what it could not get.
  const ThreadPolicy& receive_thread_policy() const { return receive_policy_; }
  void set_receive_thread_policy(ThreadPolicy policy) { receive_policy_ = std::move(policy); }

  // How the egress lane of `cls` runs (priority, CPUs; the name is the adapter's to choose). An
  // adapter whose transport runs threads of its own on behalf of one class only (a DDS
  // participant per class) runs them this way, so they rank with that class and not below it.
  const ThreadPolicy& class_thread_policy(ChannelClass cls) const {
    return class_policies_.at(static_cast<std::size_t>(cls));
  }
  void set_class_thread_policy(ChannelClass cls, ThreadPolicy policy) {
    class_policies_.at(static_cast<std::size_t>(cls)) = std::move(policy);
  }

 protected:
  ~EventSink() = default;

 private:
  ThreadPolicy receive_policy_;
  std::array<ThreadPolicy, 3> class_policies_;  // indexed by ChannelClass
};

// A channel a segment does not carry after configure(), and the transport's reason.
struct ChannelRefusal {
  ChannelId channel = kNoChannel;
  std::string reason;
};

struct Status {
  bool ok = true;
  std::string error;
  // configure() only: the bindings the segment does not carry, each with its reason (see
  // SegmentAdapter::configure for the contract every adapter keeps).
  std::vector<ChannelRefusal> refused;
  static Status success() { return {}; }
  static Status failure(std::string why) { return {false, std::move(why), {}}; }
};

enum class SendStatus { sent, queue_full, failed };

struct HealthReport {
  SegmentHealth state = SegmentHealth::up;
  std::string detail;
};

// Frames on a CAN bus that neither a bound channel, the binding protocols nor a declared background
// frame explains, by identifier: traffic admission did not know about.
struct UnexplainedFrames {
  std::uint32_t can_id = 0;  // 11 or 29 bits, without flags
  bool extended = false;
  std::uint64_t frames = 0;  // since the adapter started
  double rate_hz = 0;        // over the last full second; 0 once silent for two seconds
  friend bool operator==(const UnexplainedFrames&, const UnexplainedFrames&) = default;
};

// A counter of one transport's own (AdapterStatistics::transport).
struct TransportCounter {
  std::string name;
  std::uint64_t value = 0;
  friend bool operator==(const TransportCounter&, const TransportCounter&) = default;
};

// A fact of one transport's own, in words (AdapterStatistics::transport_notes).
struct TransportNote {
  std::string name;
  std::string text;
  friend bool operator==(const TransportNote&, const TransportNote&) = default;
};

struct AdapterStatistics {
  std::uint64_t received = 0;        // messages/frames read from the network
  std::uint64_t sent = 0;            // messages/frames written to the network
  std::uint64_t receive_errors = 0;  // malformed or unreadable input
  std::uint64_t send_errors = 0;
  std::uint64_t overflow_drops = 0;  // lost before we could read them (e.g. SO_RXQ_OVFL)
  std::uint64_t backlog = 0;         // frames waiting in the adapter's own send queue
  // What only some transports count, each under its name (docs/control-protocol.md says what each
  // means), absent where a transport has no such thing:
  //  - binding_requests_over_limit (CAN): requests of the binding protocol (GET_ETAG) over its rate
  //    limit, answered later or not at all; also counted in receive_errors;
  //  - own_datagrams_dropped (LCM with own_datagrams: drop): the datagrams the gateway sent whose
  //    looped-back copy its own receive filter dropped in the kernel, one per datagram sent; each is
  //    also one in the host's UDP InErrors and in the socket's drops, and none in overflow_drops;
  //  - unauthenticated: on an LCM segment with auth, messages without a valid tag (also replayed:
  //    with a valid tag, sent before); on a DDS segment with security, remote participants refused
  //    authentication, each counted once (transport_notes' last_unauthenticated: the last one's GUID).
  std::vector<TransportCounter> transport;
  std::vector<TransportNote> transport_notes;
  std::optional<std::uint64_t> transport_counter(std::string_view name) const {
    for (const TransportCounter& c : transport) {
      if (c.name == name) return c.value;
    }
    return std::nullopt;
  }
  // CAN: the unexplained identifiers (at most 64, lowest identifier first) and the frames of any
  // further ones; empty where the transport cannot see foreign traffic.
  std::vector<UnexplainedFrames> unexplained;
  std::uint64_t unexplained_others = 0;
};

// One rule a remote endpoint and the gateway's endpoint of a channel break (see
// SegmentAdapter::peer_qos_conflicts).
struct PeerQosConflict {
  std::string peer;    // the remote endpoint's kind: "reader" or "writer"
  std::string id;      // its identity on the transport (DDS: the GUID)
  std::string topic;   // where (DDS: the topic)
  std::string policy;  // e.g. "data_representation", "latency_budget"
  std::string reason;  // its value against ours and what follows, e.g. "requests ..., this writer offers ..."
};

class SegmentAdapter {
 public:
  virtual ~SegmentAdapter() = default;
  // The lifecycle, the same for every adapter (tests/contract/adapter_contract.hpp holds each
  // adapter to it: memory, CAN, DDS, LCM):
  //  - start() opens the transport; inbound events flow to `sink` (which must outlive stop()). A
  //    segment starts carrying nothing. start() on a started segment fails and changes nothing.
  //    A start() that fails leaves the segment not started (health down, with the reason).
  //  - configure() on a segment that is not started (before start(), after a failed start(),
  //    after stop()) fails as a whole (cosmic/binding_plan.hpp: not_started) and carries nothing.
  //  - stop() ends every thread that calls the sink and forgets the bindings: afterwards send()
  //    answers failed and health() is down ("stopped"); a later start() carries nothing until the
  //    next configure(). stop() on a segment that is not started does nothing.
  virtual Status start(EventSink& sink) = 0;
  // Makes the segment carry `bindings`. Channels present before and after keep flowing.
  //  - ok: the segment carries every binding.
  //  - !ok with Status::refused: the segment carries every binding except exactly those named:
  //    one entry per refused channel, with the transport's reason. A refused channel is carried
  //    in no role, whether or not it was before. `error` joins the reasons as "channel NAME: why".
  //    Every transport refuses a binding without channel id or name and a channel bound twice in
  //    one role (cosmic/binding_plan.hpp plans this for all of them).
  //  - !ok with refused empty: a failure of the whole segment (not started, the kernel refused
  //    its filters, ...); the segment carries exactly what it carried before the call.
  // The gateway shows each refused channel as `failed` with the reason (never bound and silent).
  virtual Status configure(std::span<const ChannelBinding> bindings) = 0;
  // Transmits one event of a channel bound here as subscriber. Never throws.
  virtual SendStatus send(const OutboundEvent& event) = 0;
  // Transmits `events` in their order, as send() one after the other would; `results[i]` is
  // events[i]'s status (results.size() == events.size()). An egress lane hands over what queued
  // up behind a send in progress, so a transport that can write several events in one system
  // call (CAN: sendmmsg) overrides this. Called by the same lane threads as send(). Never throws.
  virtual void send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) {
    for (std::size_t i = 0; i < events.size() && i < results.size(); ++i) results[i] = send(events[i]);
  }
  // True where send_batch() costs less than send() one by one (CAN, LCM: one sendmmsg). Lanes
  // hand only such an adapter several events at once, and only what queued up behind a send in
  // progress; an event's residence is then taken after its batch's send. The others (DDS: no
  // batched write) get one event at a time, each event's residence taken right after its send.
  virtual bool batches_sends() const { return false; }
  virtual HealthReport health() const = 0;
  virtual AdapterStatistics statistics() const = 0;
  // Remote endpoints discovered for `channel` here, for transports with discovery (DDS);
  // nullopt where the transport cannot know its peers (LCM multicast, CAN broadcast).
  virtual std::optional<std::size_t> matched_peers(ChannelId channel) const = 0;
  // Remote endpoints of `channel` discovered here but refused because their QoS is incompatible
  // with ours (counted each time one is refused, never reset while the channel stays bound);
  // nullopt where the transport has no such negotiation. A non-zero count is a per-channel
  // mismatch the operator must see: the peer is there and receives or sends nothing.
  virtual std::optional<std::uint64_t> incompatible_peers(ChannelId /*channel*/) const { return std::nullopt; }
  // Remote endpoints of `channel` discovered here whose QoS or type the far side refuses (or
  // neither side accepts) by rules this transport's own matching does not apply or report, so
  // that neither matched_peers nor incompatible_peers shows them (DDS: cosmic/dds_qos_match.hpp).
  // Current, not cumulative: an endpoint that goes away takes its conflicts along.
  virtual std::vector<PeerQosConflict> peer_qos_conflicts(ChannelId /*channel*/) const { return {}; }
  virtual void stop() = 0;
};

}  // namespace cosmic

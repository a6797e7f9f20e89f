// The one interface every transport implements (CAN, DDS, LCM, in-memory). It has no
// transport-specific methods: what a transport needs to know about a channel travels in
// ChannelBinding (the channel's spec plus admission's plan for this hop).
//
// Threads: start/configure/stop are called by the control thread, send() by the router thread,
// health()/statistics() by any thread. Inbound events go to the EventSink from threads the
// adapter owns, between start() and the return of stop().
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "cosmic/admission.hpp"
#include "cosmic/event.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/model.hpp"

namespace cosmic {

// One channel on this segment as admission planned it.
struct ChannelBinding {
  ChannelId id = kNoChannel;
  ChannelSpec spec;
  HopRole role = HopRole::publisher;  // publisher: the gateway receives it here; subscriber: sends it here
  std::optional<CanHopPlan> can;      // CAN segments only
};

// Why an inbound message could not become an event.
enum class InboundProblem { decode_error, unknown_channel, own_echo };

// Implemented by the router, one per segment. Called from adapter threads; never blocks long.
class EventSink {
 public:
  virtual void on_event(const InboundEvent& event) = 0;
  virtual void on_problem(ChannelId channel, InboundProblem problem) = 0;

 protected:
  ~EventSink() = default;
};

struct Status {
  bool ok = true;
  std::string error;
  static Status success() { return {}; }
  static Status failure(std::string why) { return {false, std::move(why)}; }
};

enum class SendStatus { sent, queue_full, failed };

struct HealthReport {
  SegmentHealth state = SegmentHealth::up;
  std::string detail;
};

struct AdapterStatistics {
  std::uint64_t received = 0;        // messages/frames read from the network
  std::uint64_t sent = 0;            // messages/frames written to the network
  std::uint64_t receive_errors = 0;  // malformed or unreadable input
  std::uint64_t send_errors = 0;
  std::uint64_t overflow_drops = 0;  // lost before we could read them (e.g. SO_RXQ_OVFL)
  std::uint64_t backlog = 0;         // frames waiting in the adapter's own send queue
};

class SegmentAdapter {
 public:
  virtual ~SegmentAdapter() = default;
  // Opens the transport; inbound events flow to `sink` (which must outlive stop()).
  virtual Status start(EventSink& sink) = 0;
  // Makes the segment carry exactly `bindings`. Channels present before and after keep flowing.
  virtual Status configure(std::span<const ChannelBinding> bindings) = 0;
  // Transmits one event of a channel bound here as subscriber. Never throws.
  virtual SendStatus send(const OutboundEvent& event) = 0;
  virtual HealthReport health() const = 0;
  virtual AdapterStatistics statistics() const = 0;
  // Remote endpoints discovered for `channel` here, for transports with discovery (DDS);
  // nullopt where the transport cannot know its peers (LCM multicast, CAN broadcast).
  virtual std::optional<std::size_t> matched_peers(ChannelId channel) const = 0;
  virtual void stop() = 0;
};

}  // namespace cosmic

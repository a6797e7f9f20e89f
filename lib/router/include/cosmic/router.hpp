// The router: takes events from publisher-side segments, checks them against the channel's
// admitted contract (ingress_check), applies duplicate, validity and rate policies, and queues
// them on the egress lanes of the channel's subscriber segments: one lane per (segment, class),
// each served by its own thread, so no segment and no lower class delays a higher class
// elsewhere. A receive thread that carries one class alone sends to an idle lane itself, in the
// lane thread's place (one wake-up fewer; EgressLane::push_or_send says when). Every forwarded event's residence is
// measured (from the kernel's arrival to the return of send()) and compared with gateway.residence_bound, and its age
// at egress with the channel's reaction_time (see EgressStats).
//
// Threads: inbox(i).on_event() is called from adapter threads and does the ingress work on that
// thread (one hand-off to the lane thread after it, or, for a thread of the event's class alone
// and an idle lane, the send itself: InboundEvent::receiver_class); apply(), set_segment(), snapshot() and
// stop() from the control thread. The route table is an immutable snapshot swapped atomically:
// no lock is held across any I/O. The router does not own the adapters: the caller keeps an
// adapter alive until set_segment(index, ..., nullptr) has returned (which waits for the send in
// progress on that segment).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "cosmic/channel_tap.hpp"
#include "cosmic/record_hook.hpp"
#include "cosmic/event.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/representation.hpp"
#include "cosmic/router_stats.hpp"
#include "cosmic/snapshot_table.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {

// One bound channel as the router needs it.
struct Route {
  ChannelId id = kNoChannel;
  ChannelSpec spec;
  std::vector<std::size_t> publishers;   // segment indices
  std::vector<std::size_t> subscribers;  // segment indices
  // How much later than its neighbours one event may arrive within the contract: the largest
  // latency bound of the publisher segments. The rate bucket banks 1 + ceil(this / period)
  // events, so a publisher at its period whose events the network bunches loses none.
  Nanos ingress_jitter{0};
  // A typed channel's representation on each publisher and subscriber segment, parallel to the
  // lists (cosmic/hop_representation.hpp); empty for an untyped channel, whose contents cross as
  // the bytes they came in. Ingress turns a publisher hop's message into the compact layout, each
  // egress lane the compact event into its hop's form. Derived from `spec`, so not compared.
  std::vector<std::shared_ptr<const Representation>> publisher_forms{};
  std::vector<std::shared_ptr<const Representation>> subscriber_forms{};
  friend bool operator==(const Route& a, const Route& b) {
    return a.id == b.id && a.spec == b.spec && a.publishers == b.publishers && a.subscribers == b.subscribers &&
           a.ingress_jitter == b.ingress_jitter;
  }
  const Representation* publisher_form(std::size_t segment) const;
  const Representation* subscriber_form(std::size_t hop) const {
    return hop < subscriber_forms.size() ? subscriber_forms[hop].get() : nullptr;
  }
};

struct RouterLimits {
  std::size_t hrt_queue = 256;  // events per egress lane of each class
  std::size_t srt_queue = 1024;
  std::size_t nrt_queue = 1024;
  std::size_t queue_bytes = 16u << 20;      // each lane is also bounded by bytes (large events)
  std::uint32_t rate_burst = 3;             // the least a channel's rate bucket banks (see policing_depth)
  Nanos residence_bound{Nanos(1'000'000)};  // gateway.residence_bound: what each hop is checked against
  // How the lane threads of each class run (index: ChannelClass). The name is completed with the
  // segment's name. Without lane threads (false) nothing is sent until run_once() (tests).
  std::array<ThreadPolicy, 3> lane_threads{ThreadPolicy{"hrt", 0, 0, {}}, ThreadPolicy{"srt", 0, 0, {}},
                                           ThreadPolicy{"nrt", 0, 10, {}}};
  bool threaded = true;
};

using SteadyClock = Nanos (*)();

class E2eProtection;
class EgressLane;
struct ChannelState;
class PayloadPool;
struct LaneContext;

class Router {
 public:
  // Segments live in `segment_capacity` slots; a slot keeps its index (and inbox) for the
  // router's lifetime, so a reload can add and remove segments while others keep flowing.
  Router(GatewayIdentity self, std::size_t segment_capacity, RouterLimits limits = {}, SteadyClock clock = steady_now);
  ~Router();
  Router(const Router&) = delete;
  Router& operator=(const Router&) = delete;

  // Sink to give the adapter of segment `index`.
  EventSink& inbox(std::size_t index);
  // Names slot `index` and sets the adapter that sends there; starts that segment's lane threads.
  // Each lane holds its class's queue depth (RouterLimits); SRT and NRT lanes hold
  // `lane_depth_floor` events where that is more (a CAN bus's burst: egress_lane_floor()). Null: stops them (after the
  // send in progress) and drops what they had queued. Control thread.
  void set_segment(std::size_t index, std::string name, SegmentAdapter* adapter, std::size_t lane_depth_floor = 0);
  std::size_t segment_capacity() const { return segment_names_.size(); }

  // Replaces the route table. Channels whose route is unchanged keep their counters, rate and
  // duplicate state; queued events of removed or changed channels are dropped silently.
  void apply(std::vector<Route> routes) COSMIC_EXCLUDES(apply_mutex_);

  // Without lane threads: dispatches queued events, HRT lanes first, then SRT, then NRT, until
  // none is left or `budget` were handled; returns how many.
  std::size_t run_once(std::size_t budget);
  // Stops every lane (control thread, before the adapters stop).
  void stop();

  std::vector<ChannelStatsSnapshot> snapshot() const;
  // Miss counters of the channels that missed at least once since their route was applied
  // (channels without a miss are left out: at ten thousand channels this runs every 250 ms).
  std::vector<ChannelMisses> misses() const;
  // Events the lanes have handled (sent or dropped) since start: the watchdog's progress measure.
  std::uint64_t progress() const { return progress_.load(std::memory_order_relaxed); }
  // Inbound messages that matched no bound channel, per segment.
  std::uint64_t unrouted(std::size_t segment) const;
  std::size_t queued() const;
  // The bound each hop's residence is checked against from now on (reload; control thread).
  void set_residence_bound(Nanos bound);
  // What lane threads could not get of their ThreadPolicy since the last call (control thread).
  std::vector<std::string> take_thread_problems() COSMIC_EXCLUDES(problems_mutex_);
  // Taps on channels' admitted events (cosmicctl echo; cosmic/channel_tap.hpp). Control thread.
  TapBoard& taps() { return taps_; }

  // The recorder's hook (cosmic/record_hook.hpp), or null; it must outlive the inboxes' use. Which
  // channels it sees: those `selects` (a channel's spec -> recorded) picks, now and in every later
  // apply(); an empty function selects none. Control thread.
  void set_record_hook(RecordHook* hook) { record_hook_.store(hook, std::memory_order_release); }
  void select_recorded(std::function<bool(const ChannelSpec&)> selects) COSMIC_EXCLUDES(apply_mutex_);

 private:
  struct Table;
  class SegmentInbox;

  void receive(std::size_t segment, const InboundEvent& event);
  // Whether the current routes take channel `id`'s events arriving on `segment` (any thread).
  bool routes_from(std::size_t segment, ChannelId id) const;
  void problem(std::size_t segment, ChannelId channel, InboundProblem what);
  bool admit(ChannelState& channel, SegmentCounters& counters, const InboundEvent& event);
  bool e2e_admit(ChannelState& channel, std::size_t segment, const E2eProtection& e2e,
                 std::span<const std::uint8_t> frame);
  void enqueue(const std::shared_ptr<ChannelState>& channel, std::size_t segment, const InboundEvent& event);
  std::shared_ptr<ChannelState> find(ChannelId id) const;
  EgressLane& lane(std::size_t segment, ChannelClass cls);

  GatewayIdentity self_;
  std::vector<std::string> segment_names_;
  RouterLimits limits_;
  SteadyClock clock_;
  std::vector<std::unique_ptr<SegmentInbox>> inboxes_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> unrouted_;

  // The current route table (cosmic/snapshot_table.hpp): the ingress and lane threads read it
  // with a pointer copy under its priority-inheriting mutex, never any I/O, and then use it with
  // no lock held; apply() builds the next table outside the lock, swaps it in, and frees the old
  // one itself once its last reader is done, so no forwarding thread ever frees a table.
  SnapshotTable<Table> table_;
  Mutex apply_mutex_;  // serialises apply() (control thread) against itself

  std::atomic<std::uint64_t> progress_{0};
  std::vector<std::size_t> lane_extra_;  // per segment: its lanes' depth beyond their class depths (control thread)
  std::unique_ptr<PayloadPool> pool_;
  std::unique_ptr<LaneContext> lane_context_;
  std::vector<std::unique_ptr<EgressLane>> lanes_;  // segment * 3 + class

  TapBoard taps_;
  std::atomic<RecordHook*> record_hook_{nullptr};
  std::function<bool(const ChannelSpec&)> record_selection_ COSMIC_GUARDED_BY(apply_mutex_);
  Mutex problems_mutex_;
  std::vector<std::string> thread_problems_ COSMIC_GUARDED_BY(problems_mutex_);
};

}  // namespace cosmic

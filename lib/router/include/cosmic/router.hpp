// The router: takes events from publisher-side segments, applies validity, loop, duplicate and
// rate policies, queues them by class (HRT before SRT before NRT, each queue bounded) and hands
// them to the subscriber-side segments.
//
// Threads: inbox(i).on_event() is called from adapter threads; run_once()/run() from the one
// router thread; apply()/snapshot() from the control thread. The router does not own the
// adapters: the caller keeps them alive while they are in a route table.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include "cosmic/event.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/router_policy.hpp"
#include "cosmic/router_stats.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

// One bound channel as the router needs it.
struct Route {
  ChannelId id = kNoChannel;
  ChannelSpec spec;
  std::vector<std::size_t> publishers;   // segment indices
  std::vector<std::size_t> subscribers;  // segment indices
  friend bool operator==(const Route&, const Route&) = default;
};

struct RouterLimits {
  std::size_t hrt_queue = 256;
  std::size_t srt_queue = 1024;
  std::size_t nrt_queue = 1024;
  std::size_t queue_bytes = 16u << 20;  // each class queue is also bounded by bytes (large events)
  std::uint32_t rate_burst = 3;              // events a channel may bank beyond its rate
};

using SteadyClock = Nanos (*)();
Nanos steady_now();

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
  // Names slot `index` and sets the adapter that sends there (null: slot unused). Control thread.
  void set_segment(std::size_t index, std::string name, SegmentAdapter* adapter);
  std::size_t segment_capacity() const { return segment_names_.size(); }

  // Replaces the route table. Channels whose route is unchanged keep their counters, rate and
  // duplicate state; queued events of removed or changed channels are dropped silently.
  void apply(std::vector<Route> routes);

  // Router thread: dispatches queued events until none is left or `budget` were handled;
  // returns how many. run() loops until stop().
  std::size_t run_once(std::size_t budget);
  void run();
  void stop();

  std::vector<ChannelStatsSnapshot> snapshot() const;
  // Events the router has dispatched or dropped since start: the watchdog's progress measure.
  std::uint64_t progress() const { return progress_.load(std::memory_order_relaxed); }
  // Inbound messages that matched no bound channel, per segment.
  std::uint64_t unrouted(std::size_t segment) const;
  std::size_t queued() const;

 private:
  struct ChannelState;
  struct Slot;
  class ClassQueue;
  class SegmentInbox;

  void receive(std::size_t segment, const InboundEvent& event);
  void problem(std::size_t segment, ChannelId channel, InboundProblem what);
  void dispatch(Slot& slot);
  std::shared_ptr<ChannelState> find(ChannelId id) const;
  ClassQueue& queue_for(ChannelClass cls);

  GatewayIdentity self_;
  std::vector<std::string> segment_names_;
  RouterLimits limits_;
  SteadyClock clock_;
  std::vector<std::unique_ptr<SegmentInbox>> inboxes_;
  std::vector<SegmentAdapter*> adapters_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> unrouted_;

  mutable std::shared_mutex table_mutex_;
  std::vector<std::shared_ptr<ChannelState>> table_;  // sorted by id

  std::unique_ptr<ClassQueue> hrt_;
  std::unique_ptr<ClassQueue> srt_;
  std::unique_ptr<ClassQueue> nrt_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> sleeping_{false};
  std::atomic<std::uint64_t> progress_{0};
  std::unique_ptr<Slot> scratch_;
};

}  // namespace cosmic

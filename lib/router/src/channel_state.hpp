// The router's state of one bound channel: its (immutable) route, its ingress policies and its
// counters. Shared by the route table snapshots and the events queued for it (shared_ptr), so a
// channel removed by apply() stays valid until the last queued event of it is handled.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "cosmic/pi_mutex.hpp"
#include "cosmic/router.hpp"
#include "cosmic/router_policy.hpp"
#include "cosmic/router_stats.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

struct ChannelState {
  ChannelState(Route r, std::size_t segment_count, std::uint32_t burst)
      : route(std::move(r)),
        bucket(route.spec.period.value_or(Nanos(0)),
               policing_depth(route.spec.period.value_or(Nanos(0)), route.ingress_jitter, burst)),
        counters(segment_count),
        egress(route.subscribers.size()),
        retired_egress(segment_count),
        e2e_last(segment_count),
        e2e_next(route.subscribers.size()) {}

  const Route route;
  PiMutex policy_mutex;  // guards bucket, dedup and loop_guard (ingress threads of several segments)
  TokenBucket bucket COSMIC_GUARDED_BY(policy_mutex);
  DuplicateFilter dedup COSMIC_GUARDED_BY(policy_mutex);
  RawLoopGuard loop_guard
      COSMIC_GUARDED_BY(policy_mutex);    // raw LCM channels: their events carry no origin to cut loops by
  std::vector<SegmentCounters> counters;  // indexed by segment slot
  std::vector<EgressStats> egress;        // parallel to route.subscribers
  LatencyHistogram residence;             // over every egress hop
  std::atomic<std::uint32_t> next_sequence{0};
  std::atomic<std::uint64_t> forwarded{0};
  std::atomic<bool> removed{false};
  // The recording selects this channel (Router::select_recorded): its admitted events go to the
  // record hook. Set by the control thread, read by ingress threads.
  std::atomic<bool> recorded{false};
  // Set when the route was changed under the same channel id (a replaced definition): events
  // already queued still go to the subscriber segments the new route keeps, not to the others
  // (indexed by segment slot).
  std::vector<std::atomic<bool>> retired_egress;
  // End-to-end counters of the hops whose form carries them (Representation::e2e()): the last
  // counter each publisher segment brought, plus one (0: none yet; indexed by segment slot; its
  // ingress thread), and the next one each subscriber hop writes (parallel to route.subscribers;
  // its lane thread).
  std::vector<std::atomic<std::uint64_t>> e2e_last;
  std::vector<std::atomic<std::uint64_t>> e2e_next;
};

}  // namespace cosmic

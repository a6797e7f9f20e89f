#include "cosmic/router.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include "channel_state.hpp"
#include "cosmic/e2e_protection.hpp"
#include "cosmic/ingress_check.hpp"
#include "egress_lane.hpp"
#include "payload_pool.hpp"

namespace cosmic {

namespace {
std::int64_t wall_clock_ns() {
  return std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
}
// Buffers that once held a large event give its memory back, so a burst of big NRT events does
// not pin lane-depth times their size.
constexpr std::size_t kRetainedPayloadBytes = std::size_t{64} * 1024;
constexpr std::size_t kClassCount = 3;
const char* const kClassPrefix[kClassCount] = {"hrt:", "srt:", "nrt:"};

std::size_t class_index(ChannelClass cls) { return static_cast<std::size_t>(cls); }

// Where an ingress thread puts a typed event in the compact layout: one buffer per thread that
// reads a network, grown to the largest event it has converted and then reused, so steady-state
// forwarding allocates nothing.
std::span<std::uint8_t> ingress_scratch(std::size_t size) {
  thread_local std::vector<std::uint8_t> scratch;
  if (scratch.size() < size) scratch.resize(size);
  return std::span(scratch.data(), size);
}
}  // namespace

const Representation* Route::publisher_form(std::size_t segment) const {
  for (std::size_t i = 0; i < publishers.size() && i < publisher_forms.size(); ++i) {
    if (publishers[i] == segment) return publisher_forms[i].get();
  }
  return nullptr;
}

struct Router::Table {
  std::vector<std::shared_ptr<ChannelState>> channels;  // sorted by route id
};

class Router::SegmentInbox final : public EventSink {
 public:
  SegmentInbox(Router& router, std::size_t segment) : router_(router), segment_(segment) {}
  void on_event(const InboundEvent& event) override { router_.receive(segment_, event); }
  void on_problem(ChannelId channel, InboundProblem problem) override { router_.problem(segment_, channel, problem); }
  bool routes(ChannelId channel) const override { return router_.routes_from(segment_, channel); }

 private:
  Router& router_;
  std::size_t segment_;
};

Router::Router(GatewayIdentity self, std::size_t segment_capacity, RouterLimits limits, SteadyClock clock)
    : self_(std::move(self)),
      segment_names_(segment_capacity),
      limits_(std::move(limits)),
      clock_(clock),
      unrouted_(new std::atomic<std::uint64_t>[segment_names_.size()]()),
      lane_extra_(segment_capacity, 0),
      pool_(std::make_unique<PayloadPool>(4 * (limits_.hrt_queue + limits_.srt_queue + limits_.nrt_queue),
                                          kRetainedPayloadBytes)) {
  lane_context_.reset(new LaneContext{
      clock_, limits_.residence_bound.count(), *pool_, progress_, [this](const std::vector<std::string>& problems) {
        LockGuard lock(problems_mutex_);
        thread_problems_.insert(thread_problems_.end(), problems.begin(), problems.end());
      }});
  for (std::size_t i = 0; i < segment_names_.size(); ++i) {
    inboxes_.push_back(std::make_unique<SegmentInbox>(*this, i));
    for (std::size_t c = 0; c < kClassCount; ++c)
      lanes_.push_back(std::make_unique<EgressLane>(*lane_context_, i, limits_.queue_bytes));
  }
}

Router::~Router() { stop(); }

EventSink& Router::inbox(std::size_t index) { return *inboxes_.at(index); }

EgressLane& Router::lane(std::size_t segment, ChannelClass cls) {
  return *lanes_[segment * kClassCount + class_index(cls)];
}

void Router::set_segment(std::size_t index, std::string name, SegmentAdapter* adapter, std::size_t lane_depth_floor) {
  const std::size_t depth[kClassCount] = {limits_.hrt_queue, limits_.srt_queue, limits_.nrt_queue};
  std::size_t extra = 0;
  for (std::size_t c = 0; c < kClassCount; ++c) {
    EgressLane& l = *lanes_.at(index * kClassCount + c);
    if (adapter == nullptr) {
      l.deactivate();
      continue;
    }
    ThreadPolicy policy = limits_.lane_threads[c];
    policy.name = kClassPrefix[c] + name;
    // HRT lanes keep their depth: HRT traffic is policed to its admitted rate, and an HRT event
    // that waited out a bus's burst would have missed its bound anyway.
    const bool deepened = static_cast<ChannelClass>(c) != ChannelClass::hrt;
    const std::size_t lane_depth = deepened ? std::max(depth[c], lane_depth_floor) : depth[c];
    extra += lane_depth - depth[c];
    l.activate(adapter, policy, limits_.threaded, lane_depth);
  }
  // The pool holds four times one set of class depths for every lane of every segment together;
  // lanes deeper than their class bring their excess, counted per segment so that setting a
  // segment again (a reload) does not add it twice.
  lane_extra_.at(index) = extra;
  std::size_t all_extra = 0;
  for (const std::size_t e : lane_extra_) all_extra += e;
  pool_->raise_limit(4 * (limits_.hrt_queue + limits_.srt_queue + limits_.nrt_queue) + all_extra);
  segment_names_.at(index) = std::move(name);
}

void Router::apply(std::vector<Route> routes) {
  LockGuard serial(apply_mutex_);
  // This thread alone publishes: the current table needs no reading.
  const Table& current = table_.current_for_publisher();
  Table next;
  next.channels.reserve(routes.size());
  for (auto& route : routes) {
    const auto existing = std::lower_bound(current.channels.begin(), current.channels.end(), route.id,
                                           [](const auto& s, ChannelId v) { return s->route.id < v; });
    // A route is never changed in place: ingress and lane threads read it without any lock. A
    // changed route gets a fresh state (and fresh counters).
    if (existing != current.channels.end() && (*existing)->route == route) {
      next.channels.push_back(*existing);
    } else {
      next.channels.push_back(
          std::make_shared<ChannelState>(std::move(route), segment_names_.size(), limits_.rate_burst));
      // The same channel under a changed route goes on numbering what this gateway originates:
      // a receiver's duplicate window must not take the restarted numbers for copies.
      if (existing != current.channels.end() && (*existing)->route.id == next.channels.back()->route.id) {
        next.channels.back()->next_sequence.store((*existing)->next_sequence.load());
      }
    }
  }
  std::sort(next.channels.begin(), next.channels.end(),
            [](const auto& a, const auto& b) { return a->route.id < b->route.id; });
  for (const auto& state : next.channels)
    state->recorded.store(record_selection_ && record_selection_(state->route.spec), std::memory_order_relaxed);
  for (const auto& old : current.channels) {
    const auto kept = std::lower_bound(next.channels.begin(), next.channels.end(), old->route.id,
                                       [](const auto& s, ChannelId v) { return s->route.id < v; });
    if (kept != next.channels.end() && *kept == old) continue;
    if (kept == next.channels.end() || (*kept)->route.id != old->route.id) {
      old->removed.store(true);
      continue;
    }
    // The same channel under a changed route: what is queued for a subscriber segment the new
    // route keeps is the channel's own traffic, and the segment still carries the channel id.
    const auto& stays = (*kept)->route.subscribers;
    for (const std::size_t segment : old->route.subscribers) {
      if (std::find(stays.begin(), stays.end(), segment) == stays.end() && segment < old->retired_egress.size()) {
        old->retired_egress[segment].store(true);
      }
    }
  }
  // The old table is freed here, on the control thread, once its last reader is done
  // (microseconds: readers hold it for one event or one statistics pass).
  const Table retired = SnapshotTable<Table>::retire(table_.publish(std::move(next)));
}

void Router::select_recorded(std::function<bool(const ChannelSpec&)> selects) {
  LockGuard serial(apply_mutex_);
  record_selection_ = std::move(selects);
  for (const auto& state : table_.current_for_publisher().channels)
    state->recorded.store(record_selection_ && record_selection_(state->route.spec), std::memory_order_relaxed);
}

std::shared_ptr<ChannelState> Router::find(ChannelId id) const {
  const auto table = table_.read();
  const auto it = std::lower_bound(table->channels.begin(), table->channels.end(), id,
                                   [](const auto& s, ChannelId v) { return s->route.id < v; });
  if (it == table->channels.end() || (*it)->route.id != id) return nullptr;
  return *it;
}

bool Router::routes_from(std::size_t segment, ChannelId id) const {
  const auto channel = find(id);
  if (!channel) return false;
  const auto& publishers = channel->route.publishers;
  return std::find(publishers.begin(), publishers.end(), segment) != publishers.end();
}

void Router::receive(std::size_t segment, const InboundEvent& event) {
  const auto channel = find(event.channel);
  if (!channel) {
    unrouted_[segment].fetch_add(1, std::memory_order_relaxed);
    return;
  }
  SegmentCounters& counters = channel->counters[segment];
  const auto& publishers = channel->route.publishers;
  if (std::find(publishers.begin(), publishers.end(), segment) == publishers.end()) {
    counters.drop(DropReason::no_route);
    return;
  }
  counters.rx.fetch_add(1, std::memory_order_relaxed);
  // Subject 0 means "not given" (a publisher that only knows the topic): the event is the
  // channel's. Any other subject must be the channel's own.
  InboundEvent checked = event;
  if (checked.header.subject == 0) checked.header.subject = channel->route.spec.subject;
  if (const IngressFault fault = ingress_check(checked, channel->route.spec, self_); fault != IngressFault::none) {
    counters.drop(drop_reason(fault));
    return;
  }
  // A typed channel's event goes on in the compact layout, whatever form its hop brought it in.
  if (const Representation* form = channel->route.publisher_form(segment)) {
    if (const E2eProtection* e2e = form->e2e(); e2e != nullptr && !e2e_admit(*channel, segment, *e2e, checked.payload))
      return;
    const std::span<std::uint8_t> compact = ingress_scratch(form->max_compact_size());
    const Conversion converted = form->to_compact(checked.payload, compact);
    if (!converted.ok()) {
      counters.drop(DropReason::decode_error);
      return;
    }
    checked.payload = compact.first(converted.size);
  }
  if (!admit(*channel, counters, checked)) return;
  enqueue(channel, segment, checked);
}

// A protected frame's CRC and counter (cosmic/e2e_protection.hpp): a corrupt frame and a repeated
// one go no further; a gap in the counter is counted against the channel's omission degree.
bool Router::e2e_admit(ChannelState& channel, std::size_t segment, const E2eProtection& e2e,
                       std::span<const std::uint8_t> frame) {
  SegmentCounters& counters = channel.counters[segment];
  if (frame.size() < e2e.frame_length()) {
    counters.drop(DropReason::decode_error);
    return false;
  }
  const E2eReading reading = e2e.check(frame);
  if (!reading.intact) {
    counters.drop(DropReason::corrupt);
    return false;
  }
  const std::uint64_t previous = channel.e2e_last[segment].exchange(reading.counter + std::uint64_t{1});
  const E2eStep step =
      e2e_step(previous == 0 ? std::nullopt : std::optional<std::uint32_t>(static_cast<std::uint32_t>(previous - 1)),
               reading.counter, e2e.counter_modulus());
  if (step.repeated) {
    counters.drop(DropReason::duplicate);
    return false;
  }
  if (step.omitted > 0) {
    counters.omitted.fetch_add(step.omitted, std::memory_order_relaxed);
    if (step.omitted > channel.route.spec.omission_degree)
      counters.omission_excess.fetch_add(1, std::memory_order_relaxed);
  }
  return true;
}

// Duplicate, validity and rate policies; counts what it refuses.
bool Router::admit(ChannelState& channel, SegmentCounters& counters, const InboundEvent& event) {
  const EventHeader& header = event.header;
  const ChannelSpec& spec = channel.route.spec;
  PiLock lock(channel.policy_mutex);
  const bool loop_copy = header.origin == 0 && event.identity.needs_fingerprint_loop_guard() &&
                         channel.loop_guard.loop_copy(event.payload, event.received_at);
  if (loop_copy || (header.origin != 0 && channel.dedup.seen(header.origin, header.sequence))) {
    counters.drop(DropReason::duplicate);
    return false;
  }
  if (spec.temp_validity && Nanos(header.age_ns) >= *spec.temp_validity) {
    counters.drop(DropReason::expired);
    return false;
  }
  if (!channel.bucket.admit(event.received_at)) {
    counters.drop(DropReason::rate);
    return false;
  }
  return true;
}

namespace {
// Whether the gateway also receives the channel on subscriber segment `segment`: its own reader
// is there, and a transport may hand what is sent to it within the send (Fast DDS delivers to a
// matched reader of the same process on the writing thread). Such a send never runs on a
// receive thread: that receive would run inside this one, and two of them in opposite directions
// would each wait for the reader the other is in. (During a reload a route may still lead to a
// segment whose reader of the channel is new: the DDS adapter drops a sample of its own writer as
// own_echo before the router, so that nests once and goes no further. Two DDS segments on one
// domain, which the configuration refuses unless their discovery servers differ, would match
// each other's endpoints in-process only if those servers were connected: one network configured
// as two, which this does not guard against.)
bool sends_back_in_process(const Route& route, std::size_t segment) {
  return std::find(route.publishers.begin(), route.publishers.end(), segment) != route.publishers.end();
}
}  // namespace

// Copies the payload once and queues the event on the lane of each subscriber segment.
void Router::enqueue(const std::shared_ptr<ChannelState>& channel, std::size_t segment, const InboundEvent& event) {
  const Route& route = channel->route;
  EventHeader header = event.header;
  header.hop_count = static_cast<std::uint8_t>(header.hop_count + 1);
  if (header.origin == 0) {
    // This gateway is the first to forward it: every copy carries the same origin and sequence.
    header.origin = self_.id;
    header.sequence = channel->next_sequence.fetch_add(1, std::memory_order_relaxed) + 1;
    header.created_ns = wall_clock_ns() - header.age_ns;
  }
  // A tap sees the event as it leaves (cosmicctl echo): one atomic load while none is open.
  taps_.offer(route.id, header, event.received_at, event.payload);
  // The recorder copies it into its own bounded queue or counts it dropped: never a wait here.
  if (channel->recorded.load(std::memory_order_relaxed)) {
    if (RecordHook* hook = record_hook_.load(std::memory_order_acquire))
      hook->offer(route.id, segment, header, event.received_at, event.payload);
  }
  if (route.subscribers.empty()) return;
  const auto fanout = static_cast<std::uint32_t>(route.subscribers.size());
  PayloadBuffer* buffer = pool_->acquire(event.payload, fanout);
  if (buffer == nullptr) {
    for (const std::size_t s : route.subscribers) channel->counters[s].drop(DropReason::queue_full);
    return;
  }
  // Counted before the lanes can send it (see EgressLane::forward), taken back if none took it.
  channel->forwarded.fetch_add(1, std::memory_order_relaxed);
  // A thread that carries this class alone sends to the last hop itself when that lane is idle
  // (EgressLane::push_or_send), after the other hops' lanes have their copies: they send
  // meanwhile on their own threads, and no hop waits for another hop's send.
  const std::size_t last = route.subscribers.back();
  const bool may_send_here = event.receiver_class == route.spec.cls && !sends_back_in_process(route, last);
  bool queued = false;
  for (std::uint32_t hop = 0; hop < fanout; ++hop) {
    const std::size_t s = route.subscribers[hop];
    LaneItem item{channel, buffer, header, event.received_at, hop, 0};
    EgressLane& to = lane(s, route.spec.cls);
    if (may_send_here && hop + 1 == fanout ? to.push_or_send(std::move(item)) : to.push(std::move(item))) {
      queued = true;
    } else {
      channel->counters[s].drop(DropReason::queue_full);
      pool_->release(buffer);
    }
  }
  if (!queued) channel->forwarded.fetch_sub(1, std::memory_order_relaxed);
}

namespace {
DropReason drop_reason_of(InboundProblem what) {
  switch (what) {
    case InboundProblem::decode_error:
      return DropReason::decode_error;
    case InboundProblem::unauthenticated:
      return DropReason::unauthenticated;
    case InboundProblem::replayed:
      return DropReason::replayed;
    default:
      return DropReason::no_route;
  }
}
}  // namespace

void Router::problem(std::size_t segment, ChannelId channel_id, InboundProblem what) {
  if (what == InboundProblem::own_echo) return;  // our own publication seen again: expected, not a loss
  const auto channel = channel_id == kNoChannel ? nullptr : find(channel_id);
  if (!channel) {
    unrouted_[segment].fetch_add(1, std::memory_order_relaxed);
    return;
  }
  channel->counters[segment].drop(drop_reason_of(what));
}

std::size_t Router::run_once(std::size_t budget) {
  std::size_t handled = 0;
  for (std::size_t c = 0; c < kClassCount; ++c) {
    for (std::size_t s = 0; s < segment_names_.size() && handled < budget; ++s)
      handled += lanes_[s * kClassCount + c]->run_once(budget - handled);
  }
  return handled;
}

void Router::stop() {
  for (auto& l : lanes_) l->deactivate();
}

std::size_t Router::queued() const {
  std::size_t total = 0;
  for (const auto& l : lanes_) total += l->size();
  return total;
}

void Router::set_residence_bound(Nanos bound) {
  lane_context_->residence_bound_ns.store(bound.count(), std::memory_order_relaxed);
}

std::vector<std::string> Router::take_thread_problems() {
  LockGuard lock(problems_mutex_);
  return std::exchange(thread_problems_, {});
}

std::uint64_t Router::unrouted(std::size_t segment) const { return unrouted_[segment].load(std::memory_order_relaxed); }

namespace {
HopRuntimeSnapshot hop_snapshot(const EgressStats& stats) {
  HopRuntimeSnapshot hop;
  const LatencyHistogram& h = stats.residence;
  hop.events = h.count();
  hop.residence_p50 = h.quantile(0.50);
  hop.residence_p99 = h.quantile(0.99);
  hop.residence_p999 = h.quantile(0.999);
  hop.residence_max = h.max();
  hop.residence_miss = stats.residence_miss.load(std::memory_order_relaxed);
  hop.deadline_miss = stats.deadline_miss.load(std::memory_order_relaxed);
  std::size_t last = 0;
  for (std::size_t i = 0; i < LatencyHistogram::kBuckets; ++i) {
    if (h.bucket_count(i) != 0) last = i + 1;
  }
  hop.residence_buckets.resize(last);
  for (std::size_t i = 0; i < last; ++i) hop.residence_buckets[i] = h.bucket_count(i);
  return hop;
}

SegmentCountersSnapshot counters_snapshot(const std::string& name, const SegmentCounters& c) {
  SegmentCountersSnapshot seg{name,        c.rx.load(), c.tx.load(), {}, c.omitted.load(), c.omission_excess.load(),
                              std::nullopt};
  for (std::size_t r = 0; r < kDropReasonCount; ++r) seg.dropped[r] = c.dropped[r].load();
  return seg;
}
}  // namespace

std::vector<ChannelMisses> Router::misses() const {
  const auto table = table_.read();
  std::vector<ChannelMisses> out;
  for (const auto& state : table->channels) {
    std::uint64_t residence = 0;
    std::uint64_t deadline = 0;
    for (const auto& hop : state->egress) {
      residence += hop.residence_miss.load(std::memory_order_relaxed);
      deadline += hop.deadline_miss.load(std::memory_order_relaxed);
    }
    std::uint64_t omission_excess = 0;
    for (const std::size_t s : state->route.publishers)
      omission_excess += state->counters[s].omission_excess.load(std::memory_order_relaxed);
    if (residence + deadline + omission_excess > 0)
      out.push_back(ChannelMisses{state->route.spec.name, residence, deadline, omission_excess});
  }
  return out;
}

std::vector<ChannelStatsSnapshot> Router::snapshot() const {
  const auto table = table_.read();
  std::vector<ChannelStatsSnapshot> out;
  out.reserve(table->channels.size());
  for (const auto& state : table->channels) {
    ChannelStatsSnapshot snap;
    snap.name = state->route.spec.name;
    for (const std::size_t s : state->route.publishers)
      snap.segments.push_back(counters_snapshot(segment_names_[s], state->counters[s]));
    for (std::size_t hop = 0; hop < state->route.subscribers.size(); ++hop) {
      const std::size_t s = state->route.subscribers[hop];
      SegmentCountersSnapshot seg = counters_snapshot(segment_names_[s], state->counters[s]);
      seg.egress = hop_snapshot(state->egress[hop]);
      snap.residence_miss += seg.egress->residence_miss;
      snap.deadline_miss += seg.egress->deadline_miss;
      snap.segments.push_back(std::move(seg));
    }
    snap.residence_p50 = state->residence.quantile(0.50);
    snap.residence_p99 = state->residence.quantile(0.99);
    snap.residence_p999 = state->residence.quantile(0.999);
    snap.residence_max = state->residence.max();
    snap.forwarded = state->forwarded.load();
    out.push_back(std::move(snap));
  }
  return out;
}

}  // namespace cosmic

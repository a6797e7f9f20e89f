#include "cosmic/router.hpp"

#include <algorithm>
#include <chrono>

namespace cosmic {

Nanos steady_now() {
  return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch());
}

namespace {
std::int64_t wall_clock_ns() {
  return std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
}
// Slots that once held a large event give its memory back, so a burst of big NRT events does not
// pin queue-depth times their size.
constexpr std::size_t kRetainedSlotBytes = 64 * 1024;
}  // namespace

struct Router::ChannelState {
  ChannelState(Route r, std::size_t segment_count, std::uint32_t burst)
      : route(std::move(r)), bucket(route.spec.period.value_or(Nanos(0)), burst), counters(segment_count) {}
  Route route;
  std::mutex policy_mutex;  // guards bucket and dedup (adapter threads of several segments)
  TokenBucket bucket;
  DuplicateFilter dedup;
  std::vector<SegmentCounters> counters;  // indexed by segment
  LatencyHistogram residence;
  std::atomic<std::uint32_t> next_sequence{0};
  std::atomic<std::uint64_t> forwarded{0};
  std::atomic<bool> removed{false};
};

struct Router::Slot {
  std::shared_ptr<ChannelState> channel;
  EventHeader header;
  Nanos received{0};
  std::size_t segment = 0;
  std::vector<std::uint8_t> payload;  // capacity is reused; size is the event's size
};

class Router::ClassQueue {
 public:
  ClassQueue(std::size_t depth, std::size_t byte_budget) : slots_(depth), byte_budget_(byte_budget) {}

  bool push(const std::shared_ptr<ChannelState>& channel, std::size_t segment, const InboundEvent& event) {
    std::lock_guard lock(mutex_);
    if (count_ == slots_.size() || bytes_ + event.payload.size() > byte_budget_) return false;
    Slot& slot = slots_[(head_ + count_) % slots_.size()];
    slot.channel = channel;
    slot.header = event.header;
    slot.received = event.received_at;
    slot.segment = segment;
    slot.payload.assign(event.payload.begin(), event.payload.end());
    bytes_ += event.payload.size();
    ++count_;
    return true;
  }

  // Moves the oldest event into `out` (swapping buffers, no allocation).
  bool pop(Slot& out) {
    std::lock_guard lock(mutex_);
    if (count_ == 0) return false;
    Slot& slot = slots_[head_];
    out.channel = std::move(slot.channel);
    out.header = slot.header;
    out.received = slot.received;
    out.segment = slot.segment;
    out.payload.swap(slot.payload);
    bytes_ -= out.payload.size();
    head_ = (head_ + 1) % slots_.size();
    --count_;
    return true;
  }

  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return count_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::size_t bytes_ = 0;
  std::size_t byte_budget_;
};

class Router::SegmentInbox final : public EventSink {
 public:
  SegmentInbox(Router& router, std::size_t segment) : router_(router), segment_(segment) {}
  void on_event(const InboundEvent& event) override { router_.receive(segment_, event); }
  void on_problem(ChannelId channel, InboundProblem problem) override { router_.problem(segment_, channel, problem); }

 private:
  Router& router_;
  std::size_t segment_;
};

Router::Router(GatewayIdentity self, std::size_t segment_capacity, RouterLimits limits, SteadyClock clock)
    : self_(std::move(self)),
      segment_names_(segment_capacity),
      limits_(limits),
      clock_(clock),
      adapters_(segment_names_.size(), nullptr),
      unrouted_(new std::atomic<std::uint64_t>[segment_names_.size()]()),
      hrt_(std::make_unique<ClassQueue>(limits.hrt_queue, limits.queue_bytes)),
      srt_(std::make_unique<ClassQueue>(limits.srt_queue, limits.queue_bytes)),
      nrt_(std::make_unique<ClassQueue>(limits.nrt_queue, limits.queue_bytes)),
      scratch_(std::make_unique<Slot>()) {
  for (std::size_t i = 0; i < segment_names_.size(); ++i) inboxes_.push_back(std::make_unique<SegmentInbox>(*this, i));
}

Router::~Router() = default;

EventSink& Router::inbox(std::size_t index) { return *inboxes_.at(index); }

void Router::set_segment(std::size_t index, std::string name, SegmentAdapter* adapter) {
  std::unique_lock lock(table_mutex_);
  segment_names_.at(index) = std::move(name);
  adapters_.at(index) = adapter;
}

void Router::apply(std::vector<Route> routes) {
  std::vector<std::shared_ptr<ChannelState>> table;
  table.reserve(routes.size());
  {
    std::shared_lock lock(table_mutex_);
    for (auto& route : routes) {
      auto existing = std::find_if(table_.begin(), table_.end(), [&](const auto& s) { return s->route.id == route.id; });
      // A route is never changed in place: adapter threads and the router thread read it
      // without the table lock. A changed route gets a fresh state (and fresh counters).
      if (existing != table_.end() && (*existing)->route == route) {
        table.push_back(*existing);
      } else {
        table.push_back(std::make_shared<ChannelState>(std::move(route), segment_names_.size(), limits_.rate_burst));
      }
    }
  }
  std::sort(table.begin(), table.end(), [](const auto& a, const auto& b) { return a->route.id < b->route.id; });
  std::unique_lock lock(table_mutex_);
  for (auto& old : table_) {
    const bool kept = std::any_of(table.begin(), table.end(), [&](const auto& s) { return s == old; });
    if (!kept) old->removed.store(true);
  }
  table_.swap(table);
}

std::shared_ptr<Router::ChannelState> Router::find(ChannelId id) const {
  std::shared_lock lock(table_mutex_);
  const auto it = std::lower_bound(table_.begin(), table_.end(), id, [](const auto& s, ChannelId v) { return s->route.id < v; });
  if (it == table_.end() || (*it)->route.id != id) return nullptr;
  return *it;
}

Router::ClassQueue& Router::queue_for(ChannelClass cls) {
  switch (cls) {
    case ChannelClass::hrt: return *hrt_;
    case ChannelClass::srt: return *srt_;
    case ChannelClass::nrt: return *nrt_;
  }
  return *nrt_;
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
  const EventHeader& header = event.header;
  const ChannelSpec& spec = channel->route.spec;
  {
    std::lock_guard lock(channel->policy_mutex);
    if (header.hop_count >= kMaxHops || (header.origin != 0 && header.origin == self_.id) ||
        (header.origin != 0 && channel->dedup.seen(header.origin, header.sequence))) {
      counters.drop(DropReason::duplicate);
      return;
    }
    if (spec.temp_validity && Nanos(header.age_ns) >= *spec.temp_validity) {
      counters.drop(DropReason::expired);
      return;
    }
    if (!channel->bucket.admit(event.received_at)) {
      counters.drop(DropReason::rate);
      return;
    }
  }
  if (!queue_for(spec.cls).push(channel, segment, event)) {
    counters.drop(DropReason::queue_full);
    return;
  }
  // Wake the router only when it sleeps; the fences pair with run() so no wake-up is lost.
  std::atomic_thread_fence(std::memory_order_seq_cst);
  if (sleeping_.load(std::memory_order_seq_cst)) {
    std::lock_guard lock(wake_mutex_);
    wake_.notify_one();
  }
}

void Router::problem(std::size_t segment, ChannelId channel_id, InboundProblem what) {
  if (what == InboundProblem::own_echo) return;  // our own publication seen again: expected, not a loss
  const auto channel = channel_id == kNoChannel ? nullptr : find(channel_id);
  if (!channel) {
    unrouted_[segment].fetch_add(1, std::memory_order_relaxed);
    return;
  }
  channel->counters[segment].drop(what == InboundProblem::decode_error ? DropReason::decode_error : DropReason::no_route);
}

void Router::dispatch(Slot& slot) {
  ChannelState& channel = *slot.channel;
  progress_.fetch_add(1, std::memory_order_relaxed);
  if (channel.removed.load(std::memory_order_relaxed)) return;
  const ChannelSpec& spec = channel.route.spec;
  const Nanos age = Nanos(slot.header.age_ns) + (clock_() - slot.received);
  if (spec.temp_validity && age >= *spec.temp_validity) {
    channel.counters[slot.segment].drop(DropReason::expired);
    return;
  }
  OutboundEvent out{channel.route.id, slot.header, slot.payload};
  out.header.age_ns = age.count();
  out.header.hop_count = static_cast<std::uint8_t>(slot.header.hop_count + 1);
  if (out.header.origin == 0) {
    out.header.origin = self_.id;
    out.header.sequence = channel.next_sequence.fetch_add(1, std::memory_order_relaxed) + 1;
    out.header.created_ns = wall_clock_ns() - age.count();
  }
  {
    std::shared_lock lock(table_mutex_);
    for (const std::size_t s : channel.route.subscribers) {
      SegmentAdapter* adapter = adapters_[s];
      const SendStatus status = adapter ? adapter->send(out) : SendStatus::failed;
      if (status == SendStatus::sent) {
        channel.counters[s].tx.fetch_add(1, std::memory_order_relaxed);
      } else {
        channel.counters[s].drop(status == SendStatus::queue_full ? DropReason::queue_full : DropReason::send_failed);
      }
    }
  }
  channel.forwarded.fetch_add(1, std::memory_order_relaxed);
  channel.residence.record(clock_() - slot.received);
}

std::size_t Router::run_once(std::size_t budget) {
  std::size_t handled = 0;
  Slot& slot = *scratch_;
  while (handled < budget && (hrt_->pop(slot) || srt_->pop(slot) || nrt_->pop(slot))) {
    dispatch(slot);
    slot.channel.reset();
    if (slot.payload.capacity() > kRetainedSlotBytes) std::vector<std::uint8_t>().swap(slot.payload);
    ++handled;
  }
  return handled;
}

std::size_t Router::queued() const { return hrt_->size() + srt_->size() + nrt_->size(); }

void Router::run() {
  while (!stopping_.load()) {
    if (run_once(64) > 0) continue;
    std::unique_lock lock(wake_mutex_);
    sleeping_.store(true, std::memory_order_seq_cst);
    std::atomic_thread_fence(std::memory_order_seq_cst);
    wake_.wait_for(lock, std::chrono::milliseconds(200), [&] { return stopping_.load() || queued() > 0; });
    sleeping_.store(false, std::memory_order_seq_cst);
  }
}

void Router::stop() {
  stopping_.store(true);
  std::lock_guard lock(wake_mutex_);
  wake_.notify_all();
}

std::uint64_t Router::unrouted(std::size_t segment) const { return unrouted_[segment].load(std::memory_order_relaxed); }

std::vector<ChannelStatsSnapshot> Router::snapshot() const {
  std::shared_lock lock(table_mutex_);
  std::vector<ChannelStatsSnapshot> out;
  for (const auto& state : table_) {
    ChannelStatsSnapshot snap;
    snap.name = state->route.spec.name;
    auto add = [&](std::size_t s) {
      const SegmentCounters& c = state->counters[s];
      SegmentCountersSnapshot seg{segment_names_[s], c.rx.load(), c.tx.load(), {}};
      for (std::size_t r = 0; r < kDropReasonCount; ++r) seg.dropped[r] = c.dropped[r].load();
      snap.segments.push_back(seg);
    };
    for (const std::size_t s : state->route.publishers) add(s);
    for (const std::size_t s : state->route.subscribers) add(s);
    snap.residence_p50 = state->residence.quantile(0.50);
    snap.residence_p99 = state->residence.quantile(0.99);
    snap.residence_max = state->residence.max();
    snap.forwarded = state->forwarded.load();
    out.push_back(std::move(snap));
  }
  return out;
}

}  // namespace cosmic

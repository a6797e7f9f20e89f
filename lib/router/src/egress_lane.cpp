#include "egress_lane.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <limits>

#include "cosmic/e2e_protection.hpp"

namespace cosmic {

EgressLane::EgressLane(LaneContext& context, std::size_t segment, std::size_t byte_budget)
    : context_(context), segment_(segment), byte_budget_(byte_budget) {}

EgressLane::~EgressLane() { deactivate(); }

bool EgressLane::push(LaneItem&& item) noexcept { return offer(std::move(item), false); }

bool EgressLane::push_or_send(LaneItem&& item) noexcept { return offer(std::move(item), true); }

namespace {
// The sends the calling ingress thread made itself, over every lane (send_duty.hpp).
thread_local SendDuty this_thread_sends;
}  // namespace

bool EgressLane::offer(LaneItem&& item, bool may_send_here) noexcept {
  const std::size_t size = item.payload->bytes().size();
  Nanos now{0};
  // What queues behind a send goes to an adapter that batches (LCM, CAN: one sendmmsg) in one
  // hand-over from the lane's thread, cheaper at high rates than a send per event here: DDS ->
  // cosmicd -> LCM at saturation, with such lanes sent to directly, 87k-90k events per core
  // against 99k-128k (scripts/bench, two runs each).
  if (may_send_here && batch_limit() > 1) may_send_here = false;
  if (may_send_here) {
    now = context_.clock();
    this_thread_sends.note_idle(now);
    may_send_here = !this_thread_sends.loaded() && !loaded_.load(std::memory_order_relaxed);
  }
  bool send_here = false;
  bool wake = true;
  {
    PiLock lock(mutex_);
    if (!active_) return false;
    item.generation = generation_;
    send_here = may_send_here && direct_allowed_ && !sending_ && count_ == 0;
    if (send_here) {
      sending_ = true;
      direct_sending_ = true;
      in_hand_.store(1, std::memory_order_relaxed);  // a send that hangs shows as queued (watchdog)
    } else {
      if (count_ == ring_.size() || bytes_ + size > byte_budget_) return false;
      ring_[(head_ + count_) % ring_.size()] = std::move(item);
      bytes_ += size;
      ++count_;
      // An ingress thread's send in progress wakes the lane's thread when it ends.
      wake = !direct_sending_;
    }
  }
  if (!send_here) {
    if (wake) wake_.notify_one();
    return true;
  }
  forward(item);
  const Nanos ended = context_.clock();
  this_thread_sends.note(now, ended, slow_send());
  note_send(now, ended);
  end_direct_send();
  return true;
}

Nanos EgressLane::slow_send() const noexcept {
  return Nanos(context_.residence_bound_ns.load(std::memory_order_relaxed));
}

void EgressLane::note_send(Nanos started, Nanos ended) noexcept {
  duty_.note(started, ended, slow_send());
  loaded_.store(duty_.loaded(), std::memory_order_relaxed);
}

void EgressLane::end_direct_send() noexcept {
  bool wake = false;
  {
    PiLock lock(mutex_);
    sending_ = false;
    direct_sending_ = false;
    in_hand_.store(0, std::memory_order_relaxed);
    // The lane's thread for what queued meanwhile; deactivate() waiting for this send.
    wake = count_ > 0 || !direct_allowed_;
  }
  if (wake) wake_.notify_all();
}

void EgressLane::wait_for_direct_send() noexcept {
  for (;;) {
    const std::uint32_t seen = wake_.current();
    {
      PiLock lock(mutex_);
      if (!direct_sending_) return;
    }
    wake_.wait(seen);
  }
}

std::size_t EgressLane::pop_batch(std::span<LaneItem> out) noexcept {
  PiLock lock(mutex_);
  if (direct_sending_) return 0;  // it hands over to this thread when its send returns
  std::size_t n = 0;
  for (; n < out.size() && count_ > 0; ++n) {
    out[n] = std::move(ring_[head_]);
    bytes_ -= out[n].payload->bytes().size();
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  // The lane's thread keeps sending until it finds the ring empty: then an ingress thread may.
  sending_ = n > 0;
  in_hand_.store(n, std::memory_order_relaxed);  // still counted as queued until handed over
  return n;
}

std::size_t EgressLane::size() const {
  PiLock lock(mutex_);
  return count_ + in_hand_.load(std::memory_order_relaxed);
}

std::size_t EgressLane::batch_limit() const noexcept {
  const SegmentAdapter* adapter = adapter_.load(std::memory_order_acquire);
  return adapter != nullptr && adapter->batches_sends() ? kSendBatch : 1;
}

void EgressLane::hand_over(std::span<LaneItem> items) noexcept {
  if (items.size() == 1) {
    forward(items[0]);
  } else if (items.size() > 1) {
    forward_batch(items);
  }
  in_hand_.store(0, std::memory_order_relaxed);
}

void EgressLane::activate(SegmentAdapter* adapter, const ThreadPolicy& policy, bool threaded, std::size_t depth) {
  deactivate();
  // A ring of a new depth is allocated before the lock and the old one freed after it: pushers
  // (refused while inactive) never wait for the allocator.
  // Only the control thread resizes the ring, so its size cannot change between the two locks.
  const std::size_t want = std::max<std::size_t>(1, depth);
  std::size_t current = 0;
  {
    PiLock lock(mutex_);
    current = ring_.size();
  }
  std::vector<LaneItem> ring;
  if (current != want) ring.resize(want);
  // Before the lane accepts events: an ingress thread may send the first one at once.
  adapter_.store(adapter, std::memory_order_release);
  {
    PiLock lock(mutex_);
    // deactivate() emptied the ring and head_ may point anywhere in it: a new depth starts afresh.
    if (current != want) {
      ring_.swap(ring);
      head_ = 0;
    }
    active_ = true;
    direct_allowed_ = threaded;
    // No sender runs now (deactivate() ended them): the duty starts afresh.
    duty_ = SendDuty{};
    loaded_.store(false, std::memory_order_relaxed);
    current_generation_.store(generation_, std::memory_order_release);
  }
  if (!threaded) return;
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this, policy] { worker(policy); });
}

void EgressLane::deactivate() {
  {
    PiLock lock(mutex_);
    direct_allowed_ = false;
  }
  // The adapter may be going away after this returns: an ingress thread's send ends first.
  wait_for_direct_send();
  if (thread_.joinable()) {
    running_.store(false, std::memory_order_release);
    wake_.notify_all();
    thread_.join();
  }
  std::vector<LaneItem> dropped;
  {
    PiLock lock(mutex_);
    active_ = false;
    ++generation_;  // an event pushed while this runs is discarded when next seen
    while (count_ > 0) {
      dropped.push_back(std::move(ring_[head_]));
      head_ = (head_ + 1) % ring_.size();
      --count_;
    }
    bytes_ = 0;
    sending_ = false;
  }
  adapter_.store(nullptr, std::memory_order_release);
  for (auto& item : dropped) discard(item);
}

std::size_t EgressLane::run_once(std::size_t budget) {
  std::size_t handled = 0;
  std::array<LaneItem, kSendBatch> batch;
  while (handled < budget) {
    const std::size_t n = pop_batch(std::span(batch.data(), std::min(batch_limit(), budget - handled)));
    if (n == 0) break;
    hand_over(std::span(batch.data(), n));
    handled += n;
  }
  return handled;
}

void EgressLane::worker(const ThreadPolicy& policy) {
  if (auto problems = apply_thread_policy(policy); !problems.empty() && context_.report_thread_problems) {
    for (auto& p : problems) p = "thread " + policy.name + ": " + p;
    context_.report_thread_problems(problems);
  }
  // What queued up while the last send ran goes to an adapter that batches together: one
  // hand-over (on CAN one system call) for up to kSendBatch events; the others get one at a time.
  std::array<LaneItem, kSendBatch> batch;
  for (;;) {
    // The wake-up sequence is read before running_: deactivate() clears running_ and then bumps
    // the sequence, so either this sees running_ cleared or the wait below returns at once. (The
    // other order lost that wake-up when the stop fell between the two reads: the thread slept
    // for ever and deactivate() waited for it, seen under ASan in gateway_test.)
    const std::uint32_t seen = wake_.current();
    if (!running_.load(std::memory_order_acquire)) break;
    const std::size_t n = pop_batch(std::span(batch.data(), batch_limit()));
    if (n > 0) {
      const Nanos started = context_.clock();
      hand_over(std::span(batch.data(), n));
      note_send(started, context_.clock());
      continue;
    }
    wake_.wait(seen);
  }
}

// Every item ends here, sent or dropped: that is the progress the watchdog measures.
void EgressLane::discard(LaneItem& item) noexcept {
  context_.progress.fetch_add(1, std::memory_order_relaxed);
  context_.pool.release(item.payload);
  item.payload = nullptr;
  item.channel.reset();
}

namespace {
// a + b without signed overflow (both are validated ages and residences, but a stuck clock or a
// hostile envelope must never make the arithmetic undefined).
std::int64_t saturating_add(std::int64_t a, std::int64_t b) {
  if (b > 0 && a > std::numeric_limits<std::int64_t>::max() - b) return std::numeric_limits<std::int64_t>::max();
  if (b < 0 && a < std::numeric_limits<std::int64_t>::min() - b) return std::numeric_limits<std::int64_t>::min();
  return a + b;
}
}  // namespace

std::optional<std::span<const std::uint8_t>> EgressLane::hop_bytes(LaneItem& item, std::size_t slot) noexcept {
  ChannelState& channel = *item.channel;
  const Representation* form = channel.route.subscriber_form(item.hop);
  if (form == nullptr) return item.payload->bytes();
  std::vector<std::uint8_t>& out = scratch_[slot];
  // Grows once per larger representation, never in steady state (the bound is the type's).
  if (out.size() < form->max_wire_size()) out.resize(form->max_wire_size());
  const Conversion converted = form->from_compact(item.payload->bytes(), out);
  if (converted.ok()) {
    const std::span<std::uint8_t> message(out.data(), converted.size);
    // The hop's own counter: one more for every event converted for it, so a receiver counts as
    // missing exactly the events this hop lost after here.
    if (const E2eProtection* e2e = form->e2e())
      e2e->protect(message, channel.e2e_next[item.hop].fetch_add(1, std::memory_order_relaxed));
    return message;
  }
  channel.counters[segment_].drop(converted.fault == ConversionFault::out_of_range ? DropReason::out_of_range
                                                                                   : DropReason::invalid);
  discard(item);
  return std::nullopt;
}

std::optional<OutboundEvent> EgressLane::still_wanted(LaneItem& item, std::size_t slot) noexcept {
  ChannelState& channel = *item.channel;
  if (channel.removed.load(std::memory_order_relaxed) ||
      channel.retired_egress[segment_].load(std::memory_order_relaxed) ||
      item.generation != current_generation_.load(std::memory_order_acquire)) {
    discard(item);
    return std::nullopt;
  }
  const ChannelSpec& spec = channel.route.spec;
  const Nanos waited = context_.clock() - item.received;
  const Nanos age(saturating_add(item.header.age_ns, waited.count()));
  if (spec.temp_validity && age >= *spec.temp_validity) {
    channel.counters[segment_].drop(DropReason::expired);
    if (spec.reaction_time && age > *spec.reaction_time)
      channel.egress[item.hop].deadline_miss.fetch_add(1, std::memory_order_relaxed);
    discard(item);
    return std::nullopt;
  }
  const std::optional<std::span<const std::uint8_t>> bytes = hop_bytes(item, slot);
  if (!bytes) return std::nullopt;
  OutboundEvent out{channel.route.id, item.header, *bytes};
  out.header.age_ns = age.count();
  // Counted before the send, taken back if it fails: whoever sees the event on the wire sees the
  // counter already moved.
  channel.counters[segment_].tx.fetch_add(1, std::memory_order_relaxed);
  return out;
}

void EgressLane::account(LaneItem& item, SendStatus status) noexcept {
  ChannelState& channel = *item.channel;
  SegmentCounters& counters = channel.counters[segment_];
  if (status != SendStatus::sent) {
    counters.tx.fetch_sub(1, std::memory_order_relaxed);
    counters.drop(status == SendStatus::queue_full ? DropReason::queue_full : DropReason::send_failed);
    discard(item);
    return;
  }
  const ChannelSpec& spec = channel.route.spec;
  EgressStats& hop = channel.egress[item.hop];
  const Nanos residence = context_.clock() - item.received;
  hop.residence.record(residence);
  channel.residence.record(residence);
  if (residence.count() > context_.residence_bound_ns.load(std::memory_order_relaxed))
    hop.residence_miss.fetch_add(1, std::memory_order_relaxed);
  if (spec.reaction_time && Nanos(saturating_add(item.header.age_ns, residence.count())) > *spec.reaction_time)
    hop.deadline_miss.fetch_add(1, std::memory_order_relaxed);
  discard(item);
}

void EgressLane::forward(LaneItem& item) noexcept {
  const std::optional<OutboundEvent> out = still_wanted(item, 0);
  if (!out) return;
  SegmentAdapter* adapter = adapter_.load(std::memory_order_acquire);
  account(item, adapter != nullptr ? adapter->send(*out) : SendStatus::failed);
}

// The residence of each event is taken when the whole batch is handed over: an event waits for
// the ones before it in the batch as it would have in the lane.
void EgressLane::forward_batch(std::span<LaneItem> items) noexcept {
  std::array<OutboundEvent, kSendBatch> outs;
  std::array<std::size_t, kSendBatch> which{};  // index in `items` of each event in `outs`
  std::size_t n = 0;
  for (std::size_t i = 0; i < items.size() && n < kSendBatch; ++i) {
    if (auto out = still_wanted(items[i], n)) {
      outs[n] = *out;
      which[n++] = i;
    }
  }
  if (n == 0) return;
  std::array<SendStatus, kSendBatch> statuses;
  statuses.fill(SendStatus::failed);
  SegmentAdapter* adapter = adapter_.load(std::memory_order_acquire);
  if (adapter != nullptr) adapter->send_batch(std::span(outs.data(), n), std::span(statuses.data(), n));
  for (std::size_t k = 0; k < n; ++k) account(items[which[k]], statuses[k]);
}

}  // namespace cosmic

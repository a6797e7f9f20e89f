#include "cosmic/memory_adapter.hpp"

#include <algorithm>

#include "cosmic/binding_plan.hpp"
#include "cosmic/steady_clock.hpp"

namespace cosmic {

Status MemoryAdapter::start(EventSink& sink) {
  LockGuard lock(mutex_);
  if (sink_ != nullptr) return Status::failure("segment " + segment_name_ + " already started");
  sink_ = &sink;
  health_ = HealthReport{SegmentHealth::up, ""};
  return Status::success();
}

Status MemoryAdapter::configure(std::span<const ChannelBinding> bindings) {
  LockGuard lock(mutex_);
  if (sink_ == nullptr) return not_started(segment_name_);
  if (!fail_configure_.empty()) return Status::failure(fail_configure_);
  BindingPlan plan(bindings);
  for (const ChannelBinding* b : plan.accepted()) {
    const auto refused = refuse_.find(b->spec.name);
    if (refused != refuse_.end()) plan.refuse(*b, refused->second);
  }
  bindings_ = plan.carried();
  return plan.status();
}

void MemoryAdapter::refuse_channel(const std::string& name, std::string reason) {
  LockGuard lock(mutex_);
  if (reason.empty()) {
    refuse_.erase(name);
  } else {
    refuse_[name] = std::move(reason);
  }
}

void MemoryAdapter::fail_configure(std::string reason) {
  LockGuard lock(mutex_);
  fail_configure_ = std::move(reason);
}

const ChannelBinding* MemoryAdapter::find(const std::string& name) const {
  const auto it = std::find_if(bindings_.begin(), bindings_.end(), [&](const auto& b) { return b.spec.name == name; });
  return it == bindings_.end() ? nullptr : &*it;
}

SendStatus MemoryAdapter::send(const OutboundEvent& event) {
  UniqueLock lock(mutex_);
  while (held_) lock.wait(released_);
  const auto it = std::find_if(bindings_.begin(), bindings_.end(),
                               [&](const auto& b) { return b.id == event.channel && b.role == HopRole::subscriber; });
  if (it == bindings_.end()) {
    ++stats_.send_errors;
    return SendStatus::failed;
  }
  if (congested_) return SendStatus::queue_full;
  sent_.push_back(RecordedEvent{it->spec.name, event.header, {event.payload.begin(), event.payload.end()}});
  ++stats_.sent;
  sent_changed_.notify_all();
  return SendStatus::sent;
}

void MemoryAdapter::send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) {
  {
    LockGuard lock(mutex_);
    batches_.push_back(events.size());
  }
  for (std::size_t i = 0; i < events.size() && i < results.size(); ++i) results[i] = send(events[i]);
}

std::vector<std::size_t> MemoryAdapter::batches() const {
  LockGuard lock(mutex_);
  return batches_;
}

bool MemoryAdapter::inject(const std::string& channel, std::vector<std::uint8_t> payload, EventHeader header) {
  EventSink* sink = nullptr;
  ChannelId id = kNoChannel;
  {
    LockGuard lock(mutex_);
    const ChannelBinding* binding = find(channel);
    sink = sink_;
    ++stats_.received;
    if (binding && binding->role == HopRole::publisher) {
      id = binding->id;
      if (header.subject == 0) header.subject = binding->spec.subject;
    }
  }
  if (!sink) return false;
  if (id == kNoChannel) {
    sink->on_problem(kNoChannel, InboundProblem::unknown_channel);
    return false;
  }
  sink->on_event(InboundEvent{id, header, payload, steady_now()});
  return true;
}

void MemoryAdapter::inject_garbage(const std::string& channel) {
  EventSink* sink = nullptr;
  ChannelId id = kNoChannel;
  {
    LockGuard lock(mutex_);
    sink = sink_;
    ++stats_.receive_errors;
    if (const ChannelBinding* binding = find(channel)) id = binding->id;
  }
  if (sink) sink->on_problem(id, InboundProblem::decode_error);
}

std::vector<RecordedEvent> MemoryAdapter::sent() const {
  LockGuard lock(mutex_);
  return sent_;
}

std::size_t MemoryAdapter::wait_sent(std::size_t count, std::chrono::milliseconds timeout) const {
  UniqueLock lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (sent_.size() < count && lock.wait_until(sent_changed_, deadline) != std::cv_status::timeout) {
  }
  return sent_.size();
}

HealthReport MemoryAdapter::health() const {
  LockGuard lock(mutex_);
  return health_;
}

AdapterStatistics MemoryAdapter::statistics() const {
  LockGuard lock(mutex_);
  return stats_;
}

void MemoryAdapter::stop() {
  LockGuard lock(mutex_);
  sink_ = nullptr;
  bindings_.clear();
  health_ = HealthReport{SegmentHealth::down, "stopped"};
}

void MemoryAdapter::set_health(SegmentHealth state, std::string detail) {
  LockGuard lock(mutex_);
  health_ = HealthReport{state, std::move(detail)};
}

void MemoryAdapter::hold_sends(bool hold) {
  LockGuard lock(mutex_);
  held_ = hold;
  released_.notify_all();
}

void MemoryAdapter::set_congested(bool congested) {
  LockGuard lock(mutex_);
  congested_ = congested;
}

std::vector<ChannelBinding> MemoryAdapter::bindings() const {
  LockGuard lock(mutex_);
  return bindings_;
}

std::optional<std::size_t> MemoryAdapter::matched_peers(ChannelId channel) const {
  LockGuard lock(mutex_);
  if (!discovery_) return std::nullopt;
  const auto bound =
      std::find_if(bindings_.begin(), bindings_.end(), [&](const ChannelBinding& b) { return b.id == channel; });
  if (bound == bindings_.end()) return std::nullopt;
  const auto peers = matched_.find(bound->spec.name);
  return peers == matched_.end() ? 0 : peers->second;
}

void MemoryAdapter::simulate_discovery() {
  LockGuard lock(mutex_);
  discovery_ = true;
}

void MemoryAdapter::set_matched(const std::string& channel, std::size_t peers) {
  LockGuard lock(mutex_);
  matched_[channel] = peers;
}

}  // namespace cosmic

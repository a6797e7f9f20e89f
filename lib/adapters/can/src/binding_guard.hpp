// Guards of the binding protocols (GET_ETAG, CCP) of one CAN segment, both profiles:
// - BindingRateLimit: a bus node may ask only so often; a flood of requests costs the gateway
//   a counter, not a stream of answers.
// - ProtocolQueue: answers wait here and go to the kernel one at a time, only when no
//   real-time frame waits in the adapter's backlog, paced by the bus time of a frame. The
//   kernel's transmit queue is FIFO: an answer written into it ahead of later HRT frames would
//   delay them (an inversion admission does not model); with at most one answer in flight an
//   HRT frame waits for at most one lower-priority frame, the blocking admission accounts for.
// Pure, not thread-safe: the CAN adapter uses them under its I/O lock.
#pragma once

#include <linux/can.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

#include "cosmic/units.hpp"

namespace cosmic {

class RequestBucket {
 public:
  RequestBucket() = default;
  RequestBucket(double per_second, double burst) : per_ns_(per_second / 1e9), burst_(burst), tokens_(burst) {}
  bool take(Nanos now) {
    if (started_) tokens_ = std::min(burst_, tokens_ + static_cast<double>((now - last_).count()) * per_ns_);
    started_ = true;
    last_ = now;
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

 private:
  double per_ns_ = 0;
  double burst_ = 0;
  double tokens_ = 0;
  Nanos last_{0};
  bool started_ = false;
};

// At most `per_node` requests per second from one TxNode (burst 4) and `total` per second from
// the whole bus (burst 32).
class BindingRateLimit {
 public:
  explicit BindingRateLimit(double per_node = 10, double total = 100) : total_(total, 32) {
    nodes_.fill(RequestBucket(per_node, 4));
  }
  bool admit(std::uint8_t tx_node, Nanos now) {
    // The node's own budget first, so one noisy node does not use up the bus-wide one.
    return nodes_[tx_node & 0x7F].take(now) && total_.take(now);
  }

 private:
  std::array<RequestBucket, 128> nodes_;
  RequestBucket total_;
};

class ProtocolQueue {
 public:
  // `gap`: time between two answers written to the kernel (a few frame times on the bus).
  explicit ProtocolQueue(Nanos gap, std::size_t capacity = 64) : gap_(gap), capacity_(capacity) {}

  bool room_for(std::size_t frames) const { return queue_.size() + frames <= capacity_; }
  void push(const can_frame& frame) { queue_.push_back(frame); }  // after room_for()
  bool empty() const { return queue_.empty(); }
  std::size_t size() const { return queue_.size(); }

  // The next answer when it may go now; the caller writes it and calls sent(now).
  const can_frame* due(Nanos now) const { return queue_.empty() || now < next_ ? nullptr : &queue_.front(); }
  void sent(Nanos now) {
    queue_.pop_front();
    next_ = now + gap_;
  }
  void wait(Nanos now) { next_ = now + gap_; }  // the kernel refused it for now: keep it
  std::optional<Nanos> deadline() const { return queue_.empty() ? std::nullopt : std::optional<Nanos>(next_); }
  void clear() { queue_.clear(); }

 private:
  Nanos gap_;
  std::size_t capacity_;
  std::deque<can_frame> queue_;
  Nanos next_{0};
};

}  // namespace cosmic

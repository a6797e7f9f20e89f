// Bounded send backlog of the CAN adapter: frames the kernel refused for the moment (ENOBUFS,
// EAGAIN) wait here and leave in arbitration order (the frame that would win on the bus first),
// frames of one identifier in the order they came (fragments must not overtake each other).
// Storage is allocated when the capacity is set, never per frame. Not thread-safe.
#pragma once

#include <linux/can.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "frame_key.hpp"

namespace cosmic {

class FrameBacklog {
 public:
  struct Entry {
    canfd_frame frame;
    bool fd = false;  // write CANFD_MTU bytes (else CAN_MTU)
    std::uint64_t order = 0;
  };

  // At most this many frames are taken out at once (one batched write).
  static constexpr std::size_t kMaxTaken = 16;

  explicit FrameBacklog(std::size_t capacity = 256) { set_capacity(capacity); }

  // Never drops queued frames: a smaller capacity takes effect as the backlog drains.
  void set_capacity(std::size_t capacity) {
    capacity_ = std::max<std::size_t>(1, capacity);
    heap_.reserve(capacity_);
  }
  std::size_t capacity() const { return capacity_; }
  std::size_t size() const { return heap_.size(); }
  bool empty() const { return heap_.empty(); }
  // Frames taken out and not yet settled or restored hold their places: the backlog never holds
  // more than its capacity, counting them.
  bool room_for(std::size_t frames) const { return heap_.size() + taken_ + frames <= capacity_; }

  bool push(const canfd_frame& frame, bool fd) {
    if (!room_for(1)) return false;
    heap_.push_back(Entry{frame, fd, next_order_++});
    std::push_heap(heap_.begin(), heap_.end(), later);
    return true;
  }
  const Entry& top() const { return heap_.front(); }
  void pop() {
    std::pop_heap(heap_.begin(), heap_.end(), later);
    heap_.pop_back();
  }
  // Takes the first frame out to be written without holding the backlog's lock; it keeps its
  // place in the count until settle() (written or given up) or restore() (refused).
  Entry take() {
    Entry first = heap_.front();
    pop();
    ++taken_;
    return first;
  }
  std::size_t taken() const { return taken_; }
  // `frames` taken frames are done with: the kernel took them or they were given up.
  void settle(std::size_t frames) { taken_ -= std::min(frames, taken_); }
  // A taken frame the kernel refused goes back to its place (ahead of frames of its identifier
  // queued since). Its place was held, so the backlog stays within its capacity.
  void restore(const Entry& entry) {
    settle(1);
    heap_.push_back(entry);
    std::push_heap(heap_.begin(), heap_.end(), later);
  }
  void clear() { heap_.clear(); }

 private:
  // Heap order: "a leaves after b".
  static bool later(const Entry& a, const Entry& b) {
    const std::uint32_t ia = frame_arbitration_key(a.frame.can_id);
    const std::uint32_t ib = frame_arbitration_key(b.frame.can_id);
    if (ia != ib) return ia > ib;
    return a.order > b.order;
  }

  std::vector<Entry> heap_;
  std::size_t capacity_ = 256;
  std::size_t taken_ = 0;
  std::uint64_t next_order_ = 0;
};

}  // namespace cosmic

// Bounded send backlog of the CAN adapter: frames the kernel refused for the moment (ENOBUFS,
// EAGAIN) wait here and leave lowest identifier first (the frame that would win arbitration),
// frames of one identifier in the order they came (fragments must not overtake each other).
// Storage is allocated when the capacity is set, never per frame. Not thread-safe.
#pragma once

#include <linux/can.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cosmic {

class FrameBacklog {
 public:
  struct Entry {
    canfd_frame frame;
    bool fd = false;  // write CANFD_MTU bytes (else CAN_MTU)
    std::uint64_t order = 0;
  };

  explicit FrameBacklog(std::size_t capacity = 256) { set_capacity(capacity); }

  // Never drops queued frames: a smaller capacity takes effect as the backlog drains.
  void set_capacity(std::size_t capacity) {
    capacity_ = std::max<std::size_t>(1, capacity);
    heap_.reserve(capacity_);
  }
  std::size_t capacity() const { return capacity_; }
  std::size_t size() const { return heap_.size(); }
  bool empty() const { return heap_.empty(); }
  bool room_for(std::size_t frames) const { return heap_.size() + frames <= capacity_; }

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
  void clear() { heap_.clear(); }

 private:
  // Heap order: "a leaves after b".
  static bool later(const Entry& a, const Entry& b) {
    const std::uint32_t ia = a.frame.can_id & CAN_EFF_MASK;
    const std::uint32_t ib = b.frame.can_id & CAN_EFF_MASK;
    if (ia != ib) return ia > ib;
    return a.order > b.order;
  }

  std::vector<Entry> heap_;
  std::size_t capacity_ = 256;
  std::uint64_t next_order_ = 0;
};

}  // namespace cosmic

// The recorder's queue (issue 37, docs/recording.md): records of any length from many producers
// (the ingress threads of every segment) to one consumer (the recorder's writer thread), in one
// block of memory allocated up front, after Aeron's many-to-one ring buffer. A producer claims room
// with one compare-and-swap on the tail, copies its record in and commits it by storing its length
// last; it never waits: a record that does not fit now is refused and the caller counts it. The
// consumer takes committed records in claim order, then zeroes what it took and releases the room
// in pieces (one store to the head, which every producer reads, per eighth of the ring or per
// read(), not per record).
//
// Layout: each record starts on an 8-byte boundary with an 8-byte header (u32 length including the
// header, 0 while uncommitted; u32 kind: data or padding); a record that would run past the end
// leaves a padding record there and goes to the start.
//
// Threads: try_write() on any number of threads at once; read() on one thread only.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace cosmic {

class RecordRing {
 public:
  static constexpr std::size_t kMinCapacity = 4096;
  // What the smallest record (an empty one: its header alone) takes of the ring.
  static constexpr std::size_t kMinRecordBytes = 8;

  // `capacity_bytes` rounded down to a power of two, at least kMinCapacity. Allocates and zeroes it.
  explicit RecordRing(std::size_t capacity_bytes);
  RecordRing(const RecordRing&) = delete;
  RecordRing& operator=(const RecordRing&) = delete;

  std::size_t capacity() const noexcept { return capacity_; }
  // The longest record accepted (a quarter of the capacity, so one always fits once the ring drains).
  std::size_t max_record() const noexcept { return capacity_ / 4 - kHeaderBytes; }

  // Copies the parts, one after the other, as one record. False when the record is longer than
  // max_record() or the ring has no room for it now. Never blocks, never allocates.
  bool try_write(std::span<const std::span<const std::uint8_t>> parts) noexcept;

  // Hands each committed record to `take(std::span<const std::uint8_t>)` in order, at most `limit`;
  // returns how many. Stops at the first record claimed but not yet committed. The span is valid
  // during the call only.
  template <typename Take>
  std::size_t read(Take&& take, std::size_t limit);

  // Bytes claimed and not yet released (an estimate while producers write).
  std::size_t used() const noexcept {
    // Head first: read after the tail, it could have passed it and the difference would wrap.
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    const std::uint64_t tail = tail_.load(std::memory_order_acquire);
    return tail > head ? static_cast<std::size_t>(std::min<std::uint64_t>(tail - head, capacity_)) : 0;
  }

 private:
  static constexpr std::size_t kHeaderBytes = kMinRecordBytes;
  static constexpr std::uint32_t kData = 1;
  static constexpr std::uint32_t kPadding = 2;

  static std::size_t aligned(std::size_t n) noexcept { return (n + 7) & ~std::size_t{7}; }
  std::uint8_t* at(std::uint64_t position) noexcept { return bytes_ + (position & (capacity_ - 1)); }
  static void commit(std::uint8_t* header, std::uint32_t length, std::uint32_t kind) noexcept;
  static std::uint32_t committed_length(std::uint8_t* header) noexcept;
  static std::uint32_t kind_of(const std::uint8_t* header) noexcept;
  // Zeroes the bytes from `from` to `to` and releases them to the producers.
  void release(std::uint64_t from, std::uint64_t to) noexcept;

  std::size_t capacity_;
  std::unique_ptr<std::uint64_t[]> storage_;  // 8-byte aligned
  std::uint8_t* bytes_;
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next position to claim (producers)
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next position to read (consumer)
};

template <typename Take>
std::size_t RecordRing::read(Take&& take, std::size_t limit) {
  std::size_t count = 0;
  std::uint64_t released = head_.load(std::memory_order_relaxed);
  std::uint64_t head = released;
  while (count < limit) {
    // What was taken is released in pieces of an eighth of the ring at most: a take that waits (a
    // slow write) holds back little room, and no record is met twice before its room is zeroed.
    if (head - released >= capacity_ / 8) {
      release(released, head);
      released = head;
    }
    std::uint8_t* header = at(head);
    const std::uint32_t length = committed_length(header);
    if (length == 0) break;
    if (kind_of(header) == kData) {
      take(std::span<const std::uint8_t>(header + kHeaderBytes, length - kHeaderBytes));
      ++count;
    }
    head += aligned(length);
  }
  if (head != released) release(released, head);
  return count;
}

}  // namespace cosmic

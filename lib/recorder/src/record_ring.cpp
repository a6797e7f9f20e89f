// The recorder's many-to-one queue (cosmic/record_ring.hpp).
#include "cosmic/record_ring.hpp"

#include <bit>
#include <cstring>

namespace cosmic {

RecordRing::RecordRing(std::size_t capacity_bytes)
    : capacity_(std::bit_floor(std::max(capacity_bytes, kMinCapacity))),
      storage_(new std::uint64_t[capacity_ / sizeof(std::uint64_t)]()),
      bytes_(reinterpret_cast<std::uint8_t*>(storage_.get())) {}

void RecordRing::commit(std::uint8_t* header, std::uint32_t length, std::uint32_t kind) noexcept {
  std::memcpy(header + 4, &kind, sizeof kind);
  // The length last, released: the consumer that sees it sees the kind and the contents.
  std::atomic_ref<std::uint32_t>(*reinterpret_cast<std::uint32_t*>(header)).store(length, std::memory_order_release);
}

std::uint32_t RecordRing::committed_length(std::uint8_t* header) noexcept {
  return std::atomic_ref<std::uint32_t>(*reinterpret_cast<std::uint32_t*>(header)).load(std::memory_order_acquire);
}

std::uint32_t RecordRing::kind_of(const std::uint8_t* header) noexcept {
  std::uint32_t kind = 0;
  std::memcpy(&kind, header + 4, sizeof kind);
  return kind;
}

void RecordRing::release(std::uint64_t from, std::uint64_t to) noexcept {
  // Zeroed before the room is released, so a header there reads 0 until its producer commits (no
  // producer touches these bytes before the store to the head below).
  const auto offset = static_cast<std::size_t>(from & (capacity_ - 1));
  const auto length = static_cast<std::size_t>(to - from);
  const std::size_t first = std::min(length, capacity_ - offset);
  std::memset(bytes_ + offset, 0, first);
  std::memset(bytes_, 0, length - first);  // what wrapped around to the start
  head_.store(to, std::memory_order_release);
}

bool RecordRing::try_write(std::span<const std::span<const std::uint8_t>> parts) noexcept {
  std::size_t length = kHeaderBytes;
  for (const auto& part : parts) length += part.size();
  if (length > max_record() + kHeaderBytes) return false;
  const std::size_t need = aligned(length);
  std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  std::uint64_t claim = 0;
  std::size_t to_end = 0;
  for (;;) {
    const std::uint64_t head = head_.load(std::memory_order_acquire);
    to_end = capacity_ - static_cast<std::size_t>(tail & (capacity_ - 1));
    // Not contiguous before the end: pad to the end, the record goes to the start.
    claim = need <= to_end ? need : to_end + need;
    if (tail + claim - head > capacity_) return false;
    if (tail_.compare_exchange_weak(tail, tail + claim, std::memory_order_acq_rel, std::memory_order_relaxed)) break;
  }
  std::uint64_t position = tail;
  if (claim != need) {
    commit(at(position), static_cast<std::uint32_t>(to_end), kPadding);
    position += to_end;
  }
  std::uint8_t* header = at(position);
  std::uint8_t* out = header + kHeaderBytes;
  for (const auto& part : parts) {
    if (!part.empty()) std::memcpy(out, part.data(), part.size());
    out += part.size();
  }
  commit(header, static_cast<std::uint32_t>(length), kData);
  return true;
}

}  // namespace cosmic

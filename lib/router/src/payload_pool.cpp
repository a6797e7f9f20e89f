#include "payload_pool.hpp"

#include <new>
#include <utility>

namespace cosmic {

PayloadPool::PayloadPool(std::size_t max_buffers, std::size_t retained_bytes)
    : max_buffers_(max_buffers), retained_bytes_(retained_bytes) {
  all_.reserve(max_buffers_);
}

PayloadBuffer* PayloadPool::pop_free() noexcept {
  PiLock lock(mutex_);
  if (free_ != nullptr) return std::exchange(free_, free_->next_free_);
  if (all_.size() >= max_buffers_) return nullptr;
  auto* fresh = new (std::nothrow) PayloadBuffer();
  if (fresh == nullptr) return nullptr;
  all_.emplace_back(fresh);  // cannot throw: capacity reserved up front
  return fresh;
}

void PayloadPool::raise_limit(std::size_t max_buffers) noexcept {
  PiLock lock(mutex_);
  if (max_buffers <= max_buffers_) return;
  try {
    all_.reserve(max_buffers);  // pop_free() relies on the capacity: emplace_back never throws
    max_buffers_ = max_buffers;
  } catch (...) {
    // Memory is short: the pool keeps its limit, and a lane that outgrows it counts queue_full.
  }
}

void PayloadPool::push_free(PayloadBuffer* buffer) noexcept {
  PiLock lock(mutex_);
  buffer->next_free_ = free_;
  free_ = buffer;
}

PayloadBuffer* PayloadPool::acquire(std::span<const std::uint8_t> payload, std::uint32_t references) noexcept {
  PayloadBuffer* buffer = pop_free();
  if (buffer == nullptr) return nullptr;
  try {
    buffer->bytes_.assign(payload.begin(), payload.end());  // the one copy of the event's bytes
  } catch (...) {
    push_free(buffer);
    return nullptr;
  }
  buffer->references_.store(references, std::memory_order_release);
  return buffer;
}

void PayloadPool::release(PayloadBuffer* buffer) noexcept {
  if (buffer->references_.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
  if (buffer->bytes_.capacity() > retained_bytes_) std::vector<std::uint8_t>().swap(buffer->bytes_);
  push_free(buffer);
}

}  // namespace cosmic

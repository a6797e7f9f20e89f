#include "payload_pool.hpp"

#include <algorithm>
#include <new>
#include <utility>

namespace cosmic {

PayloadPool::PayloadPool(std::size_t max_buffers, std::size_t retained_bytes)
    : max_buffers_(max_buffers), retained_bytes_(retained_bytes) {}

PayloadBuffer* PayloadPool::pop_free() noexcept {
  PiLock lock(mutex_);
  if (free_ != nullptr) return std::exchange(free_, free_->next_free_);
  if (all_.size() >= max_buffers_) return nullptr;
  std::unique_ptr<PayloadBuffer> fresh(new (std::nothrow) PayloadBuffer());
  if (fresh == nullptr) return nullptr;
  try {
    all_.push_back(std::move(fresh));  // the deque may need a block: memory short is an exhausted pool
  } catch (...) {
    return nullptr;
  }
  return all_.back().get();
}

void PayloadPool::raise_limit(std::size_t max_buffers) noexcept {
  PiLock lock(mutex_);
  max_buffers_ = std::max(max_buffers_, max_buffers);
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

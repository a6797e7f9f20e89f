// Copy-once payloads: an ingress thread copies an event's bytes once into a pooled buffer, and
// every egress lane the event is queued on holds a reference to that one copy. Buffers return to
// the pool when the last lane is done; their capacity is reused, so steady-state forwarding
// allocates nothing.
//
// Threads: acquire() on ingress threads, release() on lane threads (and the control thread when
// a lane is drained). The free list has its own mutex, held for a pointer swap only.
#pragma once

#include <atomic>
#include <deque>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "cosmic/pi_mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

class PayloadBuffer {
 public:
  std::span<const std::uint8_t> bytes() const { return bytes_; }

 private:
  friend class PayloadPool;
  std::vector<std::uint8_t> bytes_;
  std::atomic<std::uint32_t> references_{0};
  PayloadBuffer* next_free_ = nullptr;  // the pool's free list (under PayloadPool::mutex_)
};

class PayloadPool {
 public:
  // At most `max_buffers` buffers exist at once; a released buffer larger than `retained_bytes`
  // gives its memory back (one burst of big NRT events must not pin it).
  PayloadPool(std::size_t max_buffers, std::size_t retained_bytes);
  // Lets up to `max_buffers` exist (never fewer than now allowed); control thread, when a lane
  // deeper than the pool was sized for is activated. Allocates nothing.
  void raise_limit(std::size_t max_buffers) noexcept COSMIC_EXCLUDES(mutex_);
  PayloadPool(const PayloadPool&) = delete;
  PayloadPool& operator=(const PayloadPool&) = delete;

  // A buffer holding a copy of `payload`, referenced `references` times; nullptr when the pool is
  // exhausted (every buffer is queued somewhere) or memory is short.
  PayloadBuffer* acquire(std::span<const std::uint8_t> payload, std::uint32_t references) noexcept;
  // Drops one reference; the last one returns the buffer to the pool.
  void release(PayloadBuffer* buffer) noexcept;

 private:
  PayloadBuffer* pop_free() noexcept COSMIC_EXCLUDES(mutex_);
  void push_free(PayloadBuffer* buffer) noexcept COSMIC_EXCLUDES(mutex_);

  std::size_t max_buffers_ COSMIC_GUARDED_BY(mutex_);
  const std::size_t retained_bytes_;
  PiMutex mutex_;
  PayloadBuffer* free_ COSMIC_GUARDED_BY(mutex_) = nullptr;
  // Ownership; grows up to max_buffers_. A deque never moves what it holds, so a raised limit
  // needs no reallocation under the lock the ingress threads take.
  std::deque<std::unique_ptr<PayloadBuffer>> all_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace cosmic

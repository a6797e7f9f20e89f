// The LCM adapter's echo filter: tells the copy of our own publication that LCM loops back to our
// receive socket from a peer's message. Thread-safe (its own small mutex, no I/O under it).
#pragma once

#include <array>
#include <atomic>
#include <climits>
#include <cstdint>
#include <span>
#include <string_view>

#include "cosmic/event.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic::lcm_detail {

// Fingerprints of the messages we published in the last second on channels this segment also
// receives, so the copy LCM loops back to our own socket is not taken for a native publication
// (raw messages have no origin field) and is told apart from an envelope that merely carries our
// origin (a loop through another gateway, or a spoof: the router counts those).
// A received raw message that matches a live fingerprint (same channel, size and 64-bit hash,
// sent within the window) consumes it and is reported as own_echo.
// Limitation: a peer that publishes byte-identical content on the same channel within the window
// of one of our own publications has that message taken for our echo (once per fingerprint).
class EchoFilter {
 public:
  void remember(ChannelId channel, std::span<const std::uint8_t> bytes, std::int64_t now) {
    const std::uint64_t hash = hash_of(bytes);
    LockGuard lock(mutex_);
    ring_[next_] = Print{channel, static_cast<std::uint32_t>(bytes.size()), hash, now, true};
    next_ = (next_ + 1) % ring_.size();
    last_remembered_.store(now, std::memory_order_release);
  }

  bool consume(ChannelId channel, std::span<const std::uint8_t> bytes, std::int64_t now) {
    // Fast path: nothing published within the window, nothing to compare against.
    if (now - last_remembered_.load(std::memory_order_acquire) > kWindowNs) return false;
    const std::uint64_t hash = hash_of(bytes);
    const auto size = static_cast<std::uint32_t>(bytes.size());
    LockGuard lock(mutex_);
    for (Print& p : ring_) {
      if (p.live && p.channel == channel && p.size == size && p.hash == hash &&
          now - p.sent_ns <= kWindowNs) {
        p.live = false;
        return true;
      }
    }
    return false;
  }

 private:
  static constexpr std::int64_t kWindowNs = 1'000'000'000;
  struct Print {
    ChannelId channel = kNoChannel;
    std::uint32_t size = 0;
    std::uint64_t hash = 0;
    std::int64_t sent_ns = 0;
    bool live = false;
  };

  static std::uint64_t hash_of(std::span<const std::uint8_t> bytes) {
    return std::hash<std::string_view>{}(
        std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }

  Mutex mutex_;
  std::array<Print, 256> ring_ COSMIC_GUARDED_BY(mutex_){};
  std::size_t next_ COSMIC_GUARDED_BY(mutex_) = 0;
  std::atomic<std::int64_t> last_remembered_{INT64_MIN / 2};
};

}  // namespace cosmic::lcm_detail

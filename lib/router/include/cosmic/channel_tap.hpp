// Taps on running channels (`cosmicctl echo`, issue 35): a bounded copy of the events a channel
// takes in, for a person or a tool to look at, that never slows forwarding. An ingress thread
// offers each admitted event to the board; when no tap is open that is one atomic load. With taps
// open it copies the event into a free slot of the channel's tap under a lock it only tries: a tap
// that is full, or being read at that instant, misses the event and counts it instead of making
// the forwarding thread wait.
//
// Threads: offer() on ingress threads; open(), read() and close() on the control thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/event.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

// One event as a tap saw it: after the ingress checks and policing, a typed channel's in the
// compact layout.
struct TappedEvent {
  EventHeader header;
  Nanos received_at{0};  // steady clock
  std::vector<std::uint8_t> payload;
};

struct TapRead {
  std::vector<TappedEvent> events;  // oldest first
  std::uint64_t missed = 0;         // events the tap could not take since the last read (full or busy)
};

class TapBoard {
 public:
  static constexpr std::size_t kMaxTaps = 8;
  static constexpr std::size_t kSlotsPerTap = 64;

  TapBoard() = default;
  TapBoard(const TapBoard&) = delete;
  TapBoard& operator=(const TapBoard&) = delete;

  // A tap on `channel` whose slots each hold `max_payload` bytes (allocated now, never on the
  // forwarding path); nullopt when kMaxTaps are open.
  std::optional<std::uint32_t> open(ChannelId channel, std::size_t max_payload) COSMIC_EXCLUDES(control_);
  // What tap `id` took since the last read, and how many it missed; nullopt for an unknown tap.
  std::optional<TapRead> read(std::uint32_t id) COSMIC_EXCLUDES(control_);
  void close(std::uint32_t id) COSMIC_EXCLUDES(control_);
  std::size_t open_taps() const noexcept { return open_.load(std::memory_order_relaxed); }

  // Called for every admitted event (ingress thread). Never blocks.
  void offer(ChannelId channel, const EventHeader& header, Nanos received_at,
             std::span<const std::uint8_t> payload) noexcept;

 private:
  struct Slot {
    EventHeader header;
    Nanos received_at{0};
    std::vector<std::uint8_t> bytes;  // capacity max_payload, sized to the event
  };
  struct Tap {
    std::atomic<ChannelId> channel{kNoChannel};  // kNoChannel: not open
    PiMutex mutex;
    std::vector<Slot> slots COSMIC_GUARDED_BY(mutex);
    std::size_t head COSMIC_GUARDED_BY(mutex) = 0;
    std::size_t count COSMIC_GUARDED_BY(mutex) = 0;
    std::size_t max_payload COSMIC_GUARDED_BY(mutex) = 0;
    std::atomic<std::uint64_t> missed{0};
    std::uint32_t id = 0;  // control thread only
  };
  void take(Tap& tap, const EventHeader& header, Nanos received_at, std::span<const std::uint8_t> payload) noexcept;

  std::array<Tap, kMaxTaps> taps_;
  std::atomic<std::size_t> open_{0};
  PiMutex control_;  // serialises open/read/close against each other
  std::uint32_t next_id_ COSMIC_GUARDED_BY(control_) = 1;
};

}  // namespace cosmic

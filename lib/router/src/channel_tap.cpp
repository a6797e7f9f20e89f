#include "cosmic/channel_tap.hpp"

#include <algorithm>
#include <cstring>

namespace cosmic {

std::optional<std::uint32_t> TapBoard::open(ChannelId channel, std::size_t max_payload) {
  PiLock serial(control_);
  for (Tap& tap : taps_) {
    if (tap.channel.load(std::memory_order_acquire) != kNoChannel) continue;
    std::vector<Slot> slots(kSlotsPerTap);
    for (Slot& slot : slots) slot.bytes.reserve(max_payload);
    {
      PiLock lock(tap.mutex);
      tap.slots = std::move(slots);
      tap.head = 0;
      tap.count = 0;
      tap.max_payload = max_payload;
    }
    tap.missed.store(0, std::memory_order_relaxed);
    tap.id = next_id_++;
    // Published last: an ingress thread that sees the channel finds the slots ready.
    tap.channel.store(channel, std::memory_order_release);
    open_.fetch_add(1, std::memory_order_relaxed);
    return tap.id;
  }
  return std::nullopt;
}

std::optional<TapRead> TapBoard::read(std::uint32_t id) {
  PiLock serial(control_);
  for (Tap& tap : taps_) {
    if (tap.id != id || tap.channel.load(std::memory_order_acquire) == kNoChannel) continue;
    TapRead out;
    // Copied under the tap's lock, which the ingress threads only try: while this read runs they
    // count the events they could not leave here as missed, rather than wait for it.
    std::vector<TappedEvent> events;
    {
      PiLock lock(tap.mutex);
      events.reserve(tap.count);
      for (std::size_t i = 0; i < tap.count; ++i) {
        const Slot& slot = tap.slots[(tap.head + i) % tap.slots.size()];
        events.push_back(TappedEvent{slot.header, slot.received_at, slot.bytes});
      }
      tap.head = 0;
      tap.count = 0;
    }
    out.events = std::move(events);
    out.missed = tap.missed.exchange(0, std::memory_order_relaxed);
    return out;
  }
  return std::nullopt;
}

void TapBoard::close(std::uint32_t id) {
  PiLock serial(control_);
  for (Tap& tap : taps_) {
    if (tap.id != id || tap.channel.load(std::memory_order_acquire) == kNoChannel) continue;
    tap.channel.store(kNoChannel, std::memory_order_release);
    open_.fetch_sub(1, std::memory_order_relaxed);
    std::vector<Slot> freed;
    {
      // An ingress thread that read the channel before the store may still be copying: taking
      // the lock waits for it, and the slots are freed after.
      PiLock lock(tap.mutex);
      freed.swap(tap.slots);
      tap.count = 0;
    }
    tap.id = 0;
    return;
  }
}

void TapBoard::offer(ChannelId channel, const EventHeader& header, Nanos received_at,
                     std::span<const std::uint8_t> payload) noexcept {
  if (open_.load(std::memory_order_relaxed) == 0) return;
  for (Tap& tap : taps_) {
    if (tap.channel.load(std::memory_order_acquire) == channel) take(tap, header, received_at, payload);
  }
}

void TapBoard::take(Tap& tap, const EventHeader& header, Nanos received_at,
                    std::span<const std::uint8_t> payload) noexcept {
  if (!tap.mutex.try_lock()) {
    tap.missed.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  // Closed meanwhile (no slots), full, or an event larger than the slots were made for: missed.
  if (tap.slots.empty() || tap.count == tap.slots.size() || payload.size() > tap.max_payload) {
    tap.mutex.unlock();
    tap.missed.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  Slot& slot = tap.slots[(tap.head + tap.count) % tap.slots.size()];
  slot.header = header;
  slot.received_at = received_at;
  slot.bytes.assign(payload.begin(), payload.end());  // within the reserved capacity: no allocation
  ++tap.count;
  tap.mutex.unlock();
}

}  // namespace cosmic

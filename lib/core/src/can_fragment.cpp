#include "cosmic/can_fragment.hpp"

#include <algorithm>
#include <cstring>

namespace cosmic {

std::uint16_t encode_fragment_header(const FragmentHeader& header) {
  return static_cast<std::uint16_t>(((header.sequence & 0x0F) << 12) | (header.last ? 0x0800 : 0) |
                                    (header.index & kMaxFragmentIndex));
}

FragmentHeader decode_fragment_header(std::uint16_t value) {
  return FragmentHeader{static_cast<std::uint8_t>(value >> 12), (value & 0x0800) != 0,
                        static_cast<std::uint16_t>(value & kMaxFragmentIndex)};
}

std::uint32_t fragment_count(std::size_t event_bytes, std::uint32_t frame_capacity) {
  if (frame_capacity <= kFragmentHeaderBytes) return 0;
  const std::size_t per = frame_capacity - kFragmentHeaderBytes;
  return static_cast<std::uint32_t>(std::max<std::size_t>(1, (event_bytes + per - 1) / per));
}

std::size_t max_fragmented_event(std::uint32_t frame_capacity) {
  if (frame_capacity <= kFragmentHeaderBytes) return 0;
  return static_cast<std::size_t>(kMaxFragments) * (frame_capacity - kFragmentHeaderBytes);
}

// ------------------------------------------------------------------------------------ Fragmenter

Fragmenter::Fragmenter(std::span<const std::uint8_t> event, std::uint32_t frame_capacity, std::uint8_t sequence)
    : event_(event), capacity_(frame_capacity), sequence_(static_cast<std::uint8_t>(sequence & 0x0F)) {
  if (event.size() <= max_fragmented_event(frame_capacity)) count_ = fragment_count(event.size(), frame_capacity);
}

std::size_t Fragmenter::next(std::span<std::uint8_t> frame) {
  if (done() || frame.size() < capacity_) return 0;
  const std::size_t per = capacity_ - kFragmentHeaderBytes;
  const std::size_t offset = static_cast<std::size_t>(next_index_) * per;
  const std::size_t n = std::min(per, event_.size() - offset);
  const std::uint16_t header = encode_fragment_header(
      FragmentHeader{sequence_, next_index_ + 1 == count_, static_cast<std::uint16_t>(next_index_)});
  frame[0] = static_cast<std::uint8_t>(header >> 8);
  frame[1] = static_cast<std::uint8_t>(header & 0xFF);
  if (n > 0) std::memcpy(frame.data() + kFragmentHeaderBytes, event_.data() + offset, n);
  ++next_index_;
  return kFragmentHeaderBytes + n;
}

// ----------------------------------------------------------------------------------- Reassembler

Reassembler::Reassembler(ReassemblyLimits limits) : limits_(limits) {
  limits_.max_partials = std::max<std::size_t>(1, limits_.max_partials);
  slots_.resize(limits_.max_partials);
}

Reassembler::Slot* Reassembler::find(std::uint32_t source) {
  for (auto& slot : slots_) {
    if (slot.state != SlotState::empty && slot.source == source) return &slot;
  }
  return nullptr;
}

Reassembler::Slot* Reassembler::record_slot(std::uint32_t source, Slot* own) {
  if (own) return own;
  Slot* best = nullptr;
  for (auto& slot : slots_) {
    if (slot.state == SlotState::empty) return &slot;
    if (slot.state == SlotState::partial || slot.source == source) continue;
    if (!best || slot.last_activity < best->last_activity) best = &slot;
  }
  return best;
}

void Reassembler::record(Slot* own, std::uint32_t source, SlotState state, std::uint8_t sequence, std::uint16_t index,
                         Nanos now) {
  Slot* slot = record_slot(source, own);
  if (!slot) return;  // every slot holds a partial event: no room for a record, that is fine
  slot->state = state;
  slot->source = source;
  slot->sequence = sequence;
  slot->highest_index = index;
  slot->last_activity = now;
}

// A fragment, in four steps: a record of the source that went stale is forgotten; a fragment of
// the source's partial event continues it (continue_event); one of an event already finished or
// given up is ignored (known_fragment); anything else has to begin an event (begin_event).
FragmentResult Reassembler::accept(std::uint32_t source, std::span<const std::uint8_t> frame,
                                   std::size_t max_event_bytes, Nanos now) {
  FragmentResult result;
  if (frame.size() < kFragmentHeaderBytes) {
    ++counters_.malformed;
    result.outcome = FragmentOutcome::rejected;
    return result;
  }
  const FragmentHeader h = decode_fragment_header(static_cast<std::uint16_t>((frame[0] << 8) | frame[1]));
  const std::span<const std::uint8_t> data = frame.subspan(kFragmentHeaderBytes);
  Slot* own = find(source);
  if (own) forget_if_stale(*own, now, result);
  if (own && own->state == SlotState::partial) {
    if (h.sequence == own->sequence) return continue_event(*own, source, h, data, now, result);
    // The source began a new event before finishing this one: its end was lost.
    ++counters_.interrupted;
    result.dropped_event = true;
    own->state = SlotState::empty;
  }
  if (own && known_fragment(*own, h, now)) {
    result.outcome = FragmentOutcome::ignored;
    return result;
  }
  return begin_event(own, source, h, data, max_event_bytes, now, result);
}

void Reassembler::forget_if_stale(Slot& own, Nanos now, FragmentResult& result) {
  if (!stale(own, now)) return;
  if (own.state == SlotState::partial) {
    ++counters_.timeouts;
    result.dropped_event = true;
  }
  own.state = SlotState::empty;
}

FragmentResult Reassembler::give_up(Slot* own, std::uint32_t source, const FragmentHeader& h, Nanos now,
                                    std::uint64_t& counter, FragmentResult result) {
  ++counter;
  result.dropped_event = true;
  result.outcome = FragmentOutcome::rejected;
  record(own, source, SlotState::discarding, h.sequence, h.index, now);
  return result;
}

FragmentResult Reassembler::continue_event(Slot& own, std::uint32_t source, const FragmentHeader& h,
                                           std::span<const std::uint8_t> data, Nanos now, FragmentResult result) {
  if (h.index < own.next_index) {
    ++counters_.duplicates;
    result.outcome = FragmentOutcome::ignored;
    return result;
  }
  if (h.index > own.next_index) return give_up(&own, source, h, now, counters_.gaps, result);
  const std::size_t limit = own.max_bytes + (h.last ? limits_.padding_slack : 0);
  if (own.bytes.size() + data.size() > limit || (!h.last && h.index == kMaxFragmentIndex)) {
    return give_up(&own, source, h, now, counters_.oversize, result);
  }
  own.bytes.insert(own.bytes.end(), data.begin(), data.end());
  ++own.next_index;
  own.last_activity = now;
  if (!h.last) {
    result.outcome = FragmentOutcome::partial;
    return result;
  }
  ++counters_.completed;
  own.state = SlotState::finished;
  own.highest_index = h.index;
  result.outcome = FragmentOutcome::complete;
  result.event = std::span<const std::uint8_t>(own.bytes.data(), std::min(own.bytes.size(), own.max_bytes));
  return result;
}

bool Reassembler::known_fragment(Slot& own, const FragmentHeader& h, Nanos now) {
  if (own.state == SlotState::finished && h.sequence == own.sequence && h.index <= own.highest_index) {
    ++counters_.duplicates;
    return true;
  }
  if (own.state != SlotState::discarding || h.sequence != own.sequence || h.index == 0) return false;
  if (h.index < own.highest_index) {
    ++counters_.reordered;
  } else if (h.index == own.highest_index) {
    ++counters_.duplicates;
  } else {
    ++counters_.stray;
    own.highest_index = h.index;
  }
  own.last_activity = now;
  return true;
}

FragmentResult Reassembler::begin_event(Slot* own, std::uint32_t source, const FragmentHeader& h,
                                        std::span<const std::uint8_t> data, std::size_t max_event_bytes, Nanos now,
                                        FragmentResult result) {
  if (h.index != 0) return give_up(own, source, h, now, counters_.gaps, result);
  const std::size_t limit = max_event_bytes + (h.last ? limits_.padding_slack : 0);
  if (data.size() > limit) return give_up(own, source, h, now, counters_.oversize, result);
  if (h.last) {
    ++counters_.completed;
    record(own, source, SlotState::finished, h.sequence, 0, now);
    result.outcome = FragmentOutcome::complete;
    result.event = data.first(std::min(data.size(), max_event_bytes));
    return result;
  }
  Slot& target = slot_for_new_event(own, now, result);
  target.state = SlotState::partial;
  target.source = source;
  target.sequence = h.sequence;
  target.next_index = 1;
  target.highest_index = 0;
  target.max_bytes = max_event_bytes;
  target.last_activity = now;
  target.bytes.clear();
  target.bytes.reserve(max_event_bytes + limits_.padding_slack);
  target.bytes.insert(target.bytes.end(), data.begin(), data.end());
  result.outcome = FragmentOutcome::partial;
  return result;
}

Reassembler::Slot& Reassembler::slot_for_new_event(Slot* own, Nanos now, FragmentResult& result) {
  if (own) return *own;
  for (auto& slot : slots_) {
    if (slot.state == SlotState::partial && stale(slot, now)) {
      ++counters_.timeouts;
      result.displaced = slot.source;
      slot.state = SlotState::empty;
    }
    if (slot.state == SlotState::empty) return slot;
  }
  // Records of finished or dropped events give way first (oldest first), then the partial event
  // idle the longest.
  Slot* target = nullptr;
  for (auto& slot : slots_) {
    if (slot.state != SlotState::partial && (!target || slot.last_activity < target->last_activity)) target = &slot;
  }
  if (target) return *target;
  for (auto& slot : slots_) {
    if (!target || slot.last_activity < target->last_activity) target = &slot;
  }
  ++counters_.evicted;
  result.displaced = target->source;
  return *target;
}

std::size_t Reassembler::expire(Nanos now, const std::function<void(std::uint32_t)>& dropped) {
  std::size_t count = 0;
  for (auto& slot : slots_) {
    if (slot.state == SlotState::empty || !stale(slot, now)) continue;
    if (slot.state == SlotState::partial) {
      ++counters_.timeouts;
      ++count;
      if (dropped) dropped(slot.source);
    }
    slot.state = SlotState::empty;
  }
  return count;
}

std::optional<Nanos> Reassembler::next_deadline() const {
  std::optional<Nanos> earliest;
  for (const auto& slot : slots_) {
    if (slot.state != SlotState::partial) continue;
    const Nanos deadline = slot.last_activity + limits_.timeout;
    if (!earliest || deadline < *earliest) earliest = deadline;
  }
  return earliest;
}

void Reassembler::clear() {
  for (auto& slot : slots_) slot.state = SlotState::empty;
}

std::size_t Reassembler::pending() const {
  return static_cast<std::size_t>(
      std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) { return s.state == SlotState::partial; }));
}

}  // namespace cosmic

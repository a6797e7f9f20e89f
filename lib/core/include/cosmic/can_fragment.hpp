// Fragmentation of CAN events larger than one frame (docs/can-wire-format.md, "Fragmentation").
// Pure codec, no I/O, no allocation per frame.
//
// A channel whose maximum payload exceeds one frame (8 B classic, 64 B FD) sends every event as
// fragments, even a short one; a channel that fits one frame sends the payload bare. A fragment
// is a 2-byte big-endian header followed by up to (frame capacity - 2) event bytes:
//
//   bits 15..12  event sequence number, mod 16 (per sending node and etag)
//   bit  11      last fragment of the event
//   bits 10..0   fragment index, 0..2047
//
// The receiver reassembles per source (TxNode + etag). CAN neither reorders nor (in practice)
// duplicates frames of one identifier, so anything but index 0, 1, 2, ... of one sequence means a
// lost frame: the event is dropped and counted; an exact repeat of a fragment (a CAN
// retransmission seen twice) is ignored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/can_wire.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

struct FragmentHeader {
  std::uint8_t sequence = 0;  // 0..15
  bool last = false;
  std::uint16_t index = 0;  // 0..2047
  friend bool operator==(const FragmentHeader&, const FragmentHeader&) = default;
};

inline constexpr std::uint8_t kFragmentSequenceModulo = 16;
inline constexpr std::uint16_t kMaxFragmentIndex = kMaxFragments - 1;

// The 16-bit header value (sequence and index are reduced to their bit widths).
std::uint16_t encode_fragment_header(const FragmentHeader& header);
FragmentHeader decode_fragment_header(std::uint16_t value);

// True when events of a channel with this maximum payload travel as fragments.
constexpr bool needs_fragmentation(std::uint64_t max_payload, std::uint32_t frame_capacity) {
  return max_payload > frame_capacity;
}
// Fragments of one event of `event_bytes` on a fragmented channel (at least 1: an empty event
// is one header-only fragment). 0 when frame_capacity leaves no room after the header.
std::uint32_t fragment_count(std::size_t event_bytes, std::uint32_t frame_capacity);
// Largest event that fits kMaxFragments fragments.
std::size_t max_fragmented_event(std::uint32_t frame_capacity);

// Cuts one event into fragments. Views the event bytes; writes each fragment into a buffer the
// caller provides.
class Fragmenter {
 public:
  Fragmenter(std::span<const std::uint8_t> event, std::uint32_t frame_capacity, std::uint8_t sequence);

  // False when the event does not fit kMaxFragments fragments (or frame_capacity <= 2):
  // next() then writes nothing.
  bool valid() const { return count_ != 0; }
  std::uint32_t count() const { return count_; }
  bool done() const { return next_index_ >= count_; }
  // Writes the next fragment (header + data) into `frame`, which must hold frame_capacity bytes;
  // returns its length (0 when done, invalid or `frame` is too small).
  std::size_t next(std::span<std::uint8_t> frame);

 private:
  std::span<const std::uint8_t> event_;
  std::uint32_t capacity_;
  std::uint8_t sequence_;
  std::uint32_t count_ = 0;
  std::uint32_t next_index_ = 0;
};

struct ReassemblyLimits {
  std::size_t max_partials = 16;  // events under reassembly at once, all sources together
  Nanos timeout{100'000'000};     // a partial event with no new fragment for this long is dropped
  // Bytes the last fragment may carry beyond the event's maximum without being an error: on CAN
  // FD a frame is padded up to the next valid length (at most 15 bytes). The excess is cut off.
  std::size_t padding_slack = 0;
};

struct ReassemblyCounters {
  std::uint64_t completed = 0;    // events reassembled
  std::uint64_t duplicates = 0;   // fragments received twice: ignored
  std::uint64_t gaps = 0;         // events dropped because a fragment was missing
  std::uint64_t reordered = 0;    // fragments older than one already seen of their event
  std::uint64_t interrupted = 0;  // events dropped because their source began a new sequence
  std::uint64_t timeouts = 0;     // events dropped after `timeout` without a fragment
  std::uint64_t oversize = 0;     // events dropped for exceeding the maximum bytes or index
  std::uint64_t evicted = 0;      // partial events dropped to make room (max_partials reached)
  std::uint64_t malformed = 0;    // frames shorter than the header
  std::uint64_t stray = 0;        // later fragments of an event already dropped: discarded
  // Events lost to any reason.
  std::uint64_t dropped_events() const { return gaps + interrupted + timeouts + oversize + evicted; }
};

enum class FragmentOutcome {
  partial,   // stored, the event is not complete yet
  complete,  // the event is complete: FragmentResult::event
  ignored,   // duplicate, or a later fragment of an event already dropped
  rejected,  // malformed, oversize or out of order: discarded (see the counters)
};

struct FragmentResult {
  FragmentOutcome outcome = FragmentOutcome::partial;
  // complete: the event bytes, valid until the next call on the Reassembler (or, for a
  // single-fragment event, as long as the frame passed in).
  std::span<const std::uint8_t> event;
  bool dropped_event = false;  // an event of this source was given up on this fragment
  // Another source whose partial event was dropped to make room for this one (evicted, or
  // found timed out).
  std::optional<std::uint32_t> displaced;
};

// Reassembles fragments per source. `source` is any key unique per sender and channel on one
// bus; the adapter uses (TxNode << 14) | etag. Memory: at most max_partials buffers, each grown
// to its channel's maximum once and then reused.
class Reassembler {
 public:
  explicit Reassembler(ReassemblyLimits limits = {});

  // One fragment (the frame's data: header + event bytes) from `source` on a channel whose
  // events are at most `max_event_bytes` long, received at `now` (steady clock).
  FragmentResult accept(std::uint32_t source, std::span<const std::uint8_t> frame, std::size_t max_event_bytes,
                        Nanos now);
  // Drops partial events idle for longer than the timeout, calling `dropped(source)` for each;
  // returns how many were dropped.
  std::size_t expire(Nanos now, const std::function<void(std::uint32_t)>& dropped = {});
  // When the earliest partial event times out (nullopt: none pending).
  std::optional<Nanos> next_deadline() const;
  // Forgets everything (not counted as drops).
  void clear();
  std::size_t pending() const;
  const ReassemblyCounters& counters() const { return counters_; }
  const ReassemblyLimits& limits() const { return limits_; }

 private:
  enum class SlotState { empty, partial, finished, discarding };
  struct Slot {
    SlotState state = SlotState::empty;
    std::uint32_t source = 0;
    std::uint8_t sequence = 0;
    std::uint16_t next_index = 0;     // partial: index expected next
    std::uint16_t highest_index = 0;  // finished: last index; discarding: highest index seen
    std::size_t max_bytes = 0;        // partial: the event's limit
    Nanos last_activity{0};
    std::vector<std::uint8_t> bytes;
  };

  Slot* find(std::uint32_t source);
  // A slot for a record (finished / discarding) of `source`: its own, or a free one; never
  // evicts a partial event. May return nullptr.
  Slot* record_slot(std::uint32_t source, Slot* own);
  void record(Slot* own, std::uint32_t source, SlotState state, std::uint8_t sequence, std::uint16_t index, Nanos now);
  bool stale(const Slot& slot, Nanos now) const { return now - slot.last_activity > limits_.timeout; }
  // accept()'s steps (can_fragment.cpp says how they fit together).
  void forget_if_stale(Slot& own, Nanos now, FragmentResult& result);
  FragmentResult continue_event(Slot& own, std::uint32_t source, const FragmentHeader& h,
                                std::span<const std::uint8_t> data, Nanos now, FragmentResult result);
  // True when `h` belongs to an event of `own` already finished or given up (ignored, counted).
  bool known_fragment(Slot& own, const FragmentHeader& h, Nanos now);
  FragmentResult begin_event(Slot* own, std::uint32_t source, const FragmentHeader& h,
                             std::span<const std::uint8_t> data, std::size_t max_event_bytes, Nanos now,
                             FragmentResult result);
  // The slot a new partial event of a source without one goes into; evicts when every slot is busy.
  Slot& slot_for_new_event(Slot* own, Nanos now, FragmentResult& result);
  // Counts `counter`, drops the source's event and records the rest of it to be discarded.
  FragmentResult give_up(Slot* own, std::uint32_t source, const FragmentHeader& h, Nanos now, std::uint64_t& counter,
                         FragmentResult result);

  ReassemblyLimits limits_;
  ReassemblyCounters counters_;
  std::vector<Slot> slots_;
};

}  // namespace cosmic

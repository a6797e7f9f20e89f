// FAMOUSO's fragmentation protocol (AFP) as its CAN network layer uses it: no event sequence
// header, in-order delivery (docs/can-wire-format.md, "FAMOUSO profile"). Events of more than
// 8 bytes travel as frames with the identifier's fragment flag set, each starting with AFP's
// basic header. Pure code: no I/O, no clock of its own. Not thread-safe: the CAN adapter's send
// side (fragmenter, under its I/O lock) and receive thread (reassembler) each own theirs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic::famouso {

inline constexpr std::size_t kAfpMtu = 8;  // classic CAN frame

// AFP basic header: the fragment sequence number counts the fragments still to come (0 = last);
// the first fragment of an event has the "first" flag. The header grows by one byte for every
// 7 bits of sequence number: 1 byte up to 31, 2 up to 4095, 3 up to 2^19 - 1.
struct AfpHeader {
  std::uint32_t remaining = 0;  // fragment sequence number
  bool first = false;
  std::size_t length = 0;  // header bytes
};
std::optional<AfpHeader> decode_afp_header(std::span<const std::uint8_t> fragment);
// Writes the header of a fragment into `out` (at least 3 bytes); returns its length.
std::size_t encode_afp_header(std::uint32_t remaining, bool first, std::span<std::uint8_t> out);
std::size_t afp_header_length(std::uint32_t remaining);

// Number of AFP fragments of an event of `length` bytes (> kAfpMtu), as FAMOUSO counts them.
std::uint32_t afp_fragment_count(std::size_t length);

// Cuts one event into AFP fragments of at most kAfpMtu bytes, first to last.
class AfpFragmenter {
 public:
  explicit AfpFragmenter(std::span<const std::uint8_t> event);
  bool done() const { return remaining_ == 0; }
  // Writes the next fragment into `out` (kAfpMtu bytes); returns its length.
  std::size_t next(std::span<std::uint8_t> out);

 private:
  std::span<const std::uint8_t> rest_;
  std::uint32_t remaining_;  // fragments still to produce
  bool first_ = true;
};

struct AfpLimits {
  std::size_t max_partial_events = 32;
  Nanos idle_timeout{Nanos(1'000'000'000)};
};

enum class AfpOutcome { partial, complete, rejected };
struct AfpResult {
  AfpOutcome outcome = AfpOutcome::partial;
  std::span<const std::uint8_t> event;     // complete: valid until the next call
  bool dropped_event = false;              // a partial event of this source was given up
  std::optional<std::uint32_t> displaced;  // source whose partial event made room for this one
};

// Reassembles in-order AFP fragments per source (TxNode and etag). Memory: at most
// max_partial_events buffers, each bounded by the channel's payload.
class AfpReassembler {
 public:
  explicit AfpReassembler(AfpLimits limits = {});
  AfpResult accept(std::uint32_t source, std::span<const std::uint8_t> fragment, std::size_t max_event, Nanos now);
  // Drops partial events idle since before now - idle_timeout; calls dropped(source) for each.
  template <typename F>
  void expire(Nanos now, F&& dropped) {
    for (Slot& s : slots_) {
      if (s.used && now - s.last > limits_.idle_timeout) {
        s.used = false;
        dropped(s.source);
      }
    }
  }
  std::optional<Nanos> next_deadline() const;
  void clear();

 private:
  struct Slot {
    bool used = false;
    std::uint32_t source = 0;
    std::uint32_t expected = 0;  // sequence number of the next fragment
    Nanos last{0};
    std::vector<std::uint8_t> data;
  };
  Slot* find(std::uint32_t source);
  Slot& claim(std::uint32_t source, AfpResult& result);

  AfpLimits limits_;
  std::vector<Slot> slots_;
};

}  // namespace cosmic::famouso

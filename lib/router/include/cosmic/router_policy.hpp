// Per-channel admission policies of the router's hot path: rate limiting, duplicate suppression
// and the loop guard of raw channels. Fixed-size state, no allocation, not thread-safe (the
// router serialises calls per channel).
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "cosmic/units.hpp"

namespace cosmic {

// Token bucket: one token per `period`, at most `burst` tokens banked. Events beyond it are
// dropped, so a babbling source cannot exceed the rate its channel reserved.
class TokenBucket {
 public:
  TokenBucket() = default;
  TokenBucket(Nanos period, std::uint32_t burst);
  // True when an event arriving at `now` (steady clock) may pass.
  bool admit(Nanos now);
  bool limited() const { return period_.count() > 0; }

 private:
  Nanos period_{0};
  std::int64_t capacity_ns_ = 0;  // burst * period
  std::int64_t credit_ns_ = 0;
  Nanos last_{0};
  bool started_ = false;
};

// How many events a channel's TokenBucket banks: 1 + ceil(jitter / period), at least `floor` and
// at most kMaxPolicingDepth. Events sent at exactly `period` and each delayed by anything in
// [0, jitter] arrive at most that many in any instant beyond the rate, so policing on arrival
// drops none of them, while a source above its rate is cut to it after that many. (Creation
// times would absorb any bunching, but they come from the sender's clock: a babbling or
// misconfigured sender could claim any spacing, so the bucket runs on arrival.)
inline constexpr std::uint32_t kMaxPolicingDepth = 4096;
std::uint32_t policing_depth(Nanos period, Nanos jitter, std::uint32_t floor);

// Remembers recently seen (origin, sequence) pairs: a window of the last 64 sequences for each of
// up to 16 origins (least recently used origin evicted).
//
// Sequences are compared in serial-number arithmetic (RFC 1982): s is newer than h when
// (s - h) mod 2^32 lies in 1..2^31-1, so a genuine wrap after 2^32 events is just one step
// forward. Nothing from outside the window can poison it: a sequence newer than the highest moves
// the window forward, one inside it is checked against the bitmap, and one further back than the
// window is taken for a restarted origin (or a spoof): it is accepted and the window re-anchored
// on it, counted in resyncs(). The price of never losing a genuine event is that a copy arriving
// more than 64 sequences late is forwarded once more.
class DuplicateFilter {
 public:
  static constexpr std::uint32_t kWindow = 64;
  // Forward jumps larger than this are counted as resyncs too (a lost stretch, or a spoof).
  static constexpr std::uint32_t kMaxGap = 1u << 16;

  // True when this (origin, sequence) was seen before.
  bool seen(std::uint64_t origin, std::uint32_t sequence);
  // Times an origin's window was re-anchored (sequence far back or far ahead).
  std::uint64_t resyncs() const { return resyncs_; }

 private:
  struct OriginWindow {
    std::uint64_t origin = 0;
    std::uint32_t highest = 0;
    std::uint64_t bits = 0;  // bit i: highest - i seen
    std::uint64_t last_use = 0;
  };
  OriginWindow& window_of(std::uint64_t origin, std::uint32_t sequence, bool& fresh);
  std::array<OriginWindow, 16> windows_{};
  std::uint64_t clock_ = 0;
  std::uint64_t resyncs_ = 0;
};

// Loop guard for raw LCM channels, whose messages carry no origin, sequence or hop count: it
// remembers the fingerprints (64-bit hash of the bytes) of the last kEntries payloads admitted
// from native sources and takes a payload seen again within `window` for a copy of one this
// gateway already forwarded, coming back through a loop (two gateways bridging one group in
// opposite directions).
// Limits: a publisher repeating an identical payload within the window loses the repeats; a
// channel carrying more than kEntries distinct payloads per window can let a loop copy through.
class RawLoopGuard {
 public:
  static constexpr std::size_t kEntries = 64;
  static constexpr Nanos kDefaultWindow{20'000'000};  // 20 ms: several loop round trips

  explicit RawLoopGuard(Nanos window = kDefaultWindow) : window_(window) {}
  // True when `payload`, arriving at `now` (steady clock), repeats one admitted less than
  // `window` ago: a loop copy. Otherwise records it and returns false.
  bool loop_copy(std::span<const std::uint8_t> payload, Nanos now);

 private:
  struct Entry {
    std::uint64_t fingerprint = 0;
    Nanos at{0};
    bool used = false;
  };
  Nanos window_;
  std::array<Entry, kEntries> entries_{};
  std::size_t next_ = 0;  // ring position of the next record
};

}  // namespace cosmic

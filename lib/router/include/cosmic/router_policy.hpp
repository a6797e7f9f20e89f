// Per-channel admission policies of the router's hot path: rate limiting and duplicate
// suppression. Fixed-size state, no allocation, not thread-safe (the router serialises calls
// per channel).
#pragma once

#include <array>
#include <cstdint>

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

// Remembers recently seen (origin, sequence) pairs: a sliding window of 64 sequences for each of
// up to 16 origins (least recently used origin evicted).
class DuplicateFilter {
 public:
  // True when this (origin, sequence) was seen before (or is too old to tell).
  bool seen(std::uint64_t origin, std::uint32_t sequence);

 private:
  struct OriginWindow {
    std::uint64_t origin = 0;
    std::uint32_t highest = 0;
    std::uint64_t bits = 0;  // bit i: highest - i seen
    std::uint64_t last_use = 0;
  };
  std::array<OriginWindow, 16> windows_{};
  std::uint64_t clock_ = 0;
};

}  // namespace cosmic

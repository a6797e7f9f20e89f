#include "cosmic/router_policy.hpp"

#include <algorithm>

namespace cosmic {

TokenBucket::TokenBucket(Nanos period, std::uint32_t burst)
    : period_(period), capacity_ns_(period.count() * std::max<std::uint32_t>(1, burst)), credit_ns_(capacity_ns_) {}

bool TokenBucket::admit(Nanos now) {
  if (!limited()) return true;
  if (started_) {
    credit_ns_ = std::min(capacity_ns_, credit_ns_ + std::max<std::int64_t>(0, (now - last_).count()));
  }
  started_ = true;
  last_ = now;
  if (credit_ns_ < period_.count()) return false;
  credit_ns_ -= period_.count();
  return true;
}

bool DuplicateFilter::seen(std::uint64_t origin, std::uint32_t sequence) {
  ++clock_;
  auto it = std::find_if(windows_.begin(), windows_.end(), [&](const OriginWindow& w) { return w.origin == origin && w.last_use != 0; });
  if (it == windows_.end()) {
    it = std::min_element(windows_.begin(), windows_.end(),
                          [](const OriginWindow& a, const OriginWindow& b) { return a.last_use < b.last_use; });
    *it = OriginWindow{origin, sequence, 1, clock_};
    return false;
  }
  OriginWindow& w = *it;
  w.last_use = clock_;
  if (sequence > w.highest) {
    const std::uint32_t shift = sequence - w.highest;
    w.bits = shift >= 64 ? 1 : (w.bits << shift) | 1;
    w.highest = sequence;
    return false;
  }
  const std::uint32_t back = w.highest - sequence;
  if (back >= 64) return true;
  const std::uint64_t mask = std::uint64_t{1} << back;
  if (w.bits & mask) return true;
  w.bits |= mask;
  return false;
}

}  // namespace cosmic

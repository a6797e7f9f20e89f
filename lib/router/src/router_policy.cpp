#include "cosmic/router_policy.hpp"

#include <algorithm>

namespace cosmic {

TokenBucket::TokenBucket(Nanos period, std::uint32_t burst)
    : period_(period), capacity_ns_(period.count() * std::max<std::uint32_t>(1, burst)), credit_ns_(capacity_ns_) {}

std::uint32_t policing_depth(Nanos period, Nanos jitter, std::uint32_t floor) {
  std::uint64_t depth = 1;
  if (period.count() > 0 && jitter.count() > 0) {
    const auto p = static_cast<std::uint64_t>(period.count());
    const auto j = static_cast<std::uint64_t>(jitter.count());
    depth += std::min<std::uint64_t>(kMaxPolicingDepth, j / p + (j % p != 0 ? 1 : 0));
  }
  depth = std::max<std::uint64_t>(depth, floor);
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(depth, kMaxPolicingDepth));
}

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

namespace {
// (a - b) in serial-number arithmetic: positive when a is newer, in -2^31..2^31-1.
std::int64_t serial_distance(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t forward = a - b;  // modulo 2^32
  return forward < 0x80000000u ? std::int64_t{forward} : std::int64_t{forward} - (std::int64_t{1} << 32);
}
}  // namespace

DuplicateFilter::OriginWindow& DuplicateFilter::window_of(std::uint64_t origin, std::uint32_t sequence, bool& fresh) {
  auto it = std::find_if(windows_.begin(), windows_.end(),
                         [&](const OriginWindow& w) { return w.origin == origin && w.last_use != 0; });
  fresh = it == windows_.end();
  if (fresh) {
    it = std::min_element(windows_.begin(), windows_.end(),
                          [](const OriginWindow& a, const OriginWindow& b) { return a.last_use < b.last_use; });
    *it = OriginWindow{origin, sequence, 1, 0};
  }
  it->last_use = clock_;
  return *it;
}

bool DuplicateFilter::seen(std::uint64_t origin, std::uint32_t sequence) {
  ++clock_;
  bool fresh = false;
  OriginWindow& w = window_of(origin, sequence, fresh);
  if (fresh) return false;
  const std::int64_t ahead = serial_distance(sequence, w.highest);
  if (ahead > 0) {
    if (ahead > kMaxGap) ++resyncs_;
    w.bits = ahead >= kWindow ? 1 : (w.bits << ahead) | 1;
    w.highest = sequence;
    return false;
  }
  const std::uint64_t back = static_cast<std::uint64_t>(-ahead);
  if (back >= kWindow) {
    // Far behind the window: a restarted origin or a spoof. Accept and follow it, so genuine
    // events are never refused for what came before.
    ++resyncs_;
    w.highest = sequence;
    w.bits = 1;
    return false;
  }
  const std::uint64_t mask = std::uint64_t{1} << back;
  if (w.bits & mask) return true;
  w.bits |= mask;
  return false;
}

namespace {
// FNV-1a over the bytes, then the length mixed in: cheap, and an accidental collision between
// two different payloads of one channel within milliseconds is negligible.
std::uint64_t fingerprint(std::span<const std::uint8_t> bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (const std::uint8_t b : bytes) hash = (hash ^ b) * 0x100000001b3ull;
  return (hash ^ bytes.size()) * 0x100000001b3ull;
}
}  // namespace

bool RawLoopGuard::loop_copy(std::span<const std::uint8_t> payload, Nanos now) {
  const std::uint64_t print = fingerprint(payload);
  for (const Entry& e : entries_) {
    if (e.used && e.fingerprint == print && now - e.at < window_ && now >= e.at) return true;
  }
  entries_[next_] = Entry{print, now, true};
  next_ = (next_ + 1) % kEntries;
  return false;
}

}  // namespace cosmic

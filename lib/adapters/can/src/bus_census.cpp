#include "bus_census.hpp"

#include "cosmic/can_timing.hpp"
#include "frame_key.hpp"

namespace cosmic::can_census {
namespace {

// The identifier back from an arbitration key (see arbitration_key in can_timing.hpp).
UnexplainedFrames identifier_of(std::uint32_t key) {
  const bool extended = (key >> 18) & 1u;
  const std::uint32_t base = key >> 19;
  return extended ? UnexplainedFrames{base << 18 | (key & 0x3FFFFu), true, 0, 0} : UnexplainedFrames{base, false, 0, 0};
}

}  // namespace

void BusCensus::count(canid_t can_id, Nanos now) {
  LockGuard lock(mutex_);
  const std::uint32_t key = frame_arbitration_key(can_id);
  auto it = tallies_.find(key);
  if (it == tallies_.end()) {
    if (tallies_.size() >= kMaxIdentifiers) {
      ++others_;
      return;
    }
    it = tallies_.emplace(key, Tally{0, 0, now, now, 0}).first;
  }
  Tally& t = it->second;
  if (now - t.window_start >= kWindow) {
    // A window just ended: its rate stands until the next one ends. A silent gap of more than
    // one window leaves a window with no frames, whose rate is 0.
    const bool gap = now - t.window_start >= 2 * kWindow;
    t.rate_hz = gap ? 0.0 : static_cast<double>(t.in_window) / to_seconds(now - t.window_start);
    t.window_start = now;
    t.in_window = 0;
  }
  ++t.total;
  ++t.in_window;
  t.last_seen = now;
}

std::vector<UnexplainedFrames> BusCensus::snapshot(Nanos now) const {
  LockGuard lock(mutex_);
  std::vector<UnexplainedFrames> out;
  out.reserve(tallies_.size());
  for (const auto& [key, t] : tallies_) {
    UnexplainedFrames frames = identifier_of(key);
    frames.frames = t.total;
    const bool silent = now - t.last_seen >= 2 * kWindow;
    // Before the first window ends, the frames so far over one window: a new sender shows at once.
    frames.rate_hz = silent ? 0.0 : t.rate_hz > 0 ? t.rate_hz : static_cast<double>(t.in_window) / to_seconds(kWindow);
    out.push_back(frames);
  }
  return out;
}

std::uint64_t BusCensus::others() const {
  LockGuard lock(mutex_);
  return others_;
}

void BusCensus::clear() {
  LockGuard lock(mutex_);
  tallies_.clear();
  others_ = 0;
}

}  // namespace cosmic::can_census

#include "step_timing.hpp"

#include <algorithm>
#include <vector>

namespace cosmic_fmu {

void StepTiming::record(std::chrono::nanoseconds took, bool late, std::chrono::nanoseconds lateness) {
  cosmic::LockGuard lock(mutex_);
  recent_[totals_.steps % kKept] = took.count();
  ++totals_.steps;
  totals_.worst = std::max(totals_.worst, took);
  totals_.worst_recent = std::max(totals_.worst_recent, took);
  if (late) {
    ++totals_.late_steps;
    totals_.latest_lateness = lateness;
  }
}

StepTimingSnapshot StepTiming::snapshot(bool take_window) {
  std::vector<std::int64_t> kept;
  kept.reserve(kKept);  // allocated before the lock: the step thread never waits for an allocation
  StepTimingSnapshot out;
  {
    cosmic::LockGuard lock(mutex_);
    out = totals_;
    if (take_window) totals_.worst_recent = std::chrono::nanoseconds{0};
    kept.assign(recent_.begin(),
                recent_.begin() + static_cast<std::ptrdiff_t>(std::min<std::uint64_t>(totals_.steps, kKept)));
  }
  if (kept.empty()) return out;
  const auto at = [&](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(kept.size() - 1));
    std::nth_element(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(k), kept.end());
    return std::chrono::nanoseconds(kept[k]);
  };
  out.p50 = at(0.50);
  out.p99 = at(0.99);
  return out;
}

}  // namespace cosmic_fmu

#include "cosmic/denial_log.hpp"

#include <algorithm>

namespace cosmic {

std::optional<std::uint64_t> DenialLog::deny(std::uint32_t uid, std::chrono::steady_clock::time_point now) {
  auto it = bursts_.find(uid);
  if (it == bursts_.end()) {
    if (bursts_.size() >= kTrackedUids) {
      bursts_.erase(std::min_element(bursts_.begin(), bursts_.end(),
                                     [](const auto& a, const auto& b) { return a.second.last < b.second.last; }));
    }
    it = bursts_.emplace(uid, Burst{}).first;
  }
  Burst& burst = it->second;
  if (burst.count > 0 && now - burst.last >= kQuiet) burst.count = 0;  // a new burst
  burst.last = now;
  const std::uint64_t n = ++burst.count;
  if ((n & (n - 1)) != 0) return std::nullopt;  // not a power of two
  return n;
}

}  // namespace cosmic

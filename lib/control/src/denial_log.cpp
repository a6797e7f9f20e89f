#include "cosmic/denial_log.hpp"

#include <algorithm>

namespace cosmic {

namespace {

// Known commands by name; any other text is one key, so made-up commands cannot multiply bursts.
std::string command_key(std::string_view command) {
  for (const char* known : {"status", "segments", "channels", "channel", "bind", "replace", "unbind", "reload"}) {
    if (command == known) return known;
  }
  return "?";
}

}  // namespace

std::optional<std::uint64_t> DenialLog::deny(std::uint32_t uid, std::string_view command,
                                             std::chrono::steady_clock::time_point now) {
  const auto key = std::pair(uid, command_key(command));
  auto it = bursts_.find(key);
  if (it == bursts_.end()) {
    if (bursts_.size() >= kTracked) {
      bursts_.erase(std::min_element(bursts_.begin(), bursts_.end(),
                                     [](const auto& a, const auto& b) { return a.second.last < b.second.last; }));
    }
    it = bursts_.emplace(key, Burst{}).first;
  }
  Burst& burst = it->second;
  if (burst.count > 0 && now - burst.last >= kQuiet) burst.count = 0;  // a new burst
  burst.last = now;
  const std::uint64_t n = ++burst.count;
  if ((n & (n - 1)) != 0) return std::nullopt;  // not a power of two
  return n;
}

}  // namespace cosmic

// Which denied control requests get a log line (issue 22, item 2): a peer sending thousands of
// requests it may not make must not turn into thousands of log lines. Per uid, the 1st, 2nd,
// 4th, 8th, ... denial of a burst is logged, each line saying how many there were so far, so
// 20,000 denials write 15 lines and the latest line always has the count. A uid quiet for
// kQuiet starts a new burst. At most kTrackedUids uids are remembered (the least recently denied
// one is forgotten first). Control thread only; `now` is the steady clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>

namespace cosmic {

class DenialLog {
 public:
  static constexpr std::chrono::seconds kQuiet{60};
  static constexpr std::size_t kTrackedUids = 256;

  // The count of this uid's denials in the current burst when this one is to be logged, else
  // nullopt (counted, not logged).
  std::optional<std::uint64_t> deny(std::uint32_t uid, std::chrono::steady_clock::time_point now);

 private:
  struct Burst {
    std::uint64_t count = 0;
    std::chrono::steady_clock::time_point last{};
  };
  std::map<std::uint32_t, Burst> bursts_;
};

}  // namespace cosmic

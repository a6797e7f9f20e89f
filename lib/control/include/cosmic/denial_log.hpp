// Which denied control requests get a log line (issue 22, item 2): a peer sending thousands of
// requests it may not make must not turn into thousands of log lines. Per uid and command (the
// known commands by name, every other text as one), the 1st, 2nd, 4th, 8th, ... denial of a
// burst is logged, each line saying how many there were so far, so 20,000 denials write 15 lines
// and the latest line always has the count. A burst quiet for kQuiet starts over. At most
// kTracked bursts are remembered (the least recently denied one is forgotten first). Control
// thread only; `now` is the steady clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace cosmic {

class DenialLog {
 public:
  static constexpr std::chrono::seconds kQuiet{60};
  static constexpr std::size_t kTracked = 256;

  // The count of this burst's denials when this one is to be logged, else nullopt (counted, not
  // logged). `command`: the request's command text (only known commands are told apart).
  std::optional<std::uint64_t> deny(std::uint32_t uid, std::string_view command,
                                    std::chrono::steady_clock::time_point now);

 private:
  struct Burst {
    std::uint64_t count = 0;
    std::chrono::steady_clock::time_point last{};
  };
  std::map<std::pair<std::uint32_t, std::string>, Burst> bursts_;
};

}  // namespace cosmic

// The one logging facade. The library never prints: components get a Logger& from their owner
// (cosmicd routes it to journald-friendly output). Implementations must be thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace cosmic {

enum class LogLevel { debug, info, notice, warning, error };

class Logger {
 public:
  virtual void log(LogLevel level, std::string_view message) = 0;

 protected:
  ~Logger() = default;
};

// Identity of this gateway on the networks: `id` tags every event it originates (envelope
// origin) so it can recognise its own publications and cut loops.
struct GatewayIdentity {
  std::uint64_t id = 0;  // random per process start, never 0
  std::string name;
};

}  // namespace cosmic

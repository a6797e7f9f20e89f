// Talks to the service manager (sd_notify): READY=1 once every segment is up (or after a grace
// period, with the missing ones named in STATUS), STATUS= with a one-line summary, and
// WATCHDOG=1 only while the router makes progress (or has nothing to do).
// Called from the control thread only. Without NOTIFY_SOCKET every call is a no-op.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "cosmic/gateway.hpp"

namespace cosmicd {

class ServiceNotifier {
 public:
  explicit ServiceNotifier(std::chrono::milliseconds ready_grace = std::chrono::seconds(10));
  // Call periodically from the control loop.
  void tick(const cosmic::Gateway& gateway);
  void reloading();
  void reloaded(const cosmic::Gateway& gateway);
  void stopping();

  // The STATUS line. Counting verdicts builds every channel's report (milliseconds at ten
  // thousand channels), so the counts are reused until the bindings or a segment's health change,
  // or for at most kVerdictRecount.
  std::string summary(const cosmic::Gateway& gateway);

 private:
  static constexpr std::chrono::seconds kVerdictRecount{5};
  const cosmic::Gateway::VerdictCounts& verdict_counts(const cosmic::Gateway& gateway, const std::string& health_key);
  bool router_alive(const cosmic::Gateway& gateway);

  cosmic::Gateway::VerdictCounts counts_;
  std::uint64_t counts_generation_ = 0;
  std::string counts_health_;
  std::chrono::steady_clock::time_point counts_at_{};
  bool counts_valid_ = false;

  std::chrono::steady_clock::time_point started_;
  std::chrono::milliseconds ready_grace_;
  std::chrono::microseconds watchdog_interval_{0};
  std::chrono::steady_clock::time_point last_ping_{};
  bool ready_sent_ = false;
  std::string last_status_;
  std::uint64_t last_progress_ = 0;
  std::size_t last_queued_ = 0;
};

}  // namespace cosmicd

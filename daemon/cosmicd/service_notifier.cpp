#include "service_notifier.hpp"

#include <systemd/sd-daemon.h>

namespace cosmicd {

ServiceNotifier::ServiceNotifier(std::chrono::milliseconds ready_grace)
    : started_(std::chrono::steady_clock::now()), ready_grace_(ready_grace) {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) watchdog_interval_ = std::chrono::microseconds(usec / 2);
}

const cosmic::Gateway::VerdictCounts& ServiceNotifier::verdict_counts(const cosmic::Gateway& gateway,
                                                                      const std::string& health_key) {
  const auto now = std::chrono::steady_clock::now();
  if (counts_valid_ && counts_generation_ == gateway.generation() && counts_health_ == health_key &&
      now - counts_at_ < kVerdictRecount) {
    return counts_;
  }
  counts_ = gateway.verdict_counts();
  counts_generation_ = gateway.generation();
  counts_health_ = health_key;
  counts_at_ = now;
  counts_valid_ = true;
  return counts_;
}

std::string ServiceNotifier::summary(const cosmic::Gateway& gateway) {
  std::size_t up = 0;
  std::string down;
  const auto segments = gateway.segments();
  for (const auto& s : segments) {
    if (s.health.state == cosmic::SegmentHealth::up) {
      ++up;
    } else {
      down += (down.empty() ? "" : ", ") + s.spec.name + " " + cosmic::to_string(s.health.state);
    }
  }
  const cosmic::Gateway::VerdictCounts& counts = verdict_counts(gateway, down);
  std::string line = std::to_string(up) + "/" + std::to_string(segments.size()) + " segments up, " +
                     std::to_string(counts.bound) + " channels bound, " + std::to_string(counts.degraded) +
                     " degraded, " + std::to_string(gateway.router().progress()) + " events handled";
  if (counts.failed > 0) line += ", " + std::to_string(counts.failed) + " FAILED (refused by their transport)";
  if (const std::size_t violated = gateway.violated_channels(); violated > 0)
    line += ", " + std::to_string(violated) + " VIOLATED (measured beyond admitted bounds)";
  if (!down.empty()) line += " (" + down + ")";
  return line;
}

bool ServiceNotifier::router_alive(const cosmic::Gateway& gateway) {
  const std::uint64_t progress = gateway.router().progress();
  const std::size_t queued = gateway.router().queued();
  // Stalled: events were waiting at the last check and none has been handled since.
  const bool stalled = last_queued_ > 0 && queued > 0 && progress == last_progress_;
  last_progress_ = progress;
  last_queued_ = queued;
  return !stalled;
}

void ServiceNotifier::tick(const cosmic::Gateway& gateway) {
  const auto now = std::chrono::steady_clock::now();
  const std::string status = summary(gateway);
  if (!ready_sent_ && (gateway.all_segments_up() || now - started_ >= ready_grace_)) {
    sd_notifyf(0, "READY=1\nSTATUS=%s", status.c_str());
    ready_sent_ = true;
    last_status_ = status;
  } else if (status != last_status_) {
    sd_notifyf(0, "STATUS=%s", status.c_str());
    last_status_ = status;
  }
  if (watchdog_interval_.count() > 0 && now - last_ping_ >= watchdog_interval_) {
    if (router_alive(gateway)) sd_notify(0, "WATCHDOG=1");
    last_ping_ = now;
  }
}

void ServiceNotifier::reloading() {
  const auto now = std::chrono::duration_cast<std::chrono::microseconds>(
      std::chrono::steady_clock::now().time_since_epoch());  // CLOCK_MONOTONIC, as systemd expects
  sd_notifyf(0, "RELOADING=1\nMONOTONIC_USEC=%lld", static_cast<long long>(now.count()));
}

void ServiceNotifier::reloaded(const cosmic::Gateway& gateway) {
  last_status_ = summary(gateway);
  sd_notifyf(0, "READY=1\nSTATUS=%s", last_status_.c_str());
}

void ServiceNotifier::stopping() { sd_notify(0, "STOPPING=1\nSTATUS=stopping"); }

}  // namespace cosmicd

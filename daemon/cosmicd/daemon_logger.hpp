// cosmicd's Logger: spdlog to stderr. Under systemd (JOURNAL_STREAM set) every line starts with
// a syslog priority prefix "<N>" that journald understands, and the timestamp is left to the
// journal. Identical messages repeated within a second are folded into one "repeated N times"
// line so a flapping bus cannot flood the journal.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <string>

#include "cosmic/log.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace spdlog {
class logger;
}

namespace cosmicd {

// "debug", "notice", "warning", "error" as their level; anything else (the command lines check
// the word) info.
cosmic::LogLevel parse_log_level(const std::string& text);

class DaemonLogger final : public cosmic::Logger {
 public:
  explicit DaemonLogger(cosmic::LogLevel threshold, std::chrono::milliseconds repeat_window = std::chrono::seconds(1));
  void log(cosmic::LogLevel level, std::string_view message) override;

 private:
  struct Repeat {
    std::chrono::steady_clock::time_point window_start;
    std::uint64_t suppressed = 0;
  };
  cosmic::LogLevel threshold_;
  std::chrono::milliseconds repeat_window_;
  bool journald_;
  std::shared_ptr<spdlog::logger> sink_;
  cosmic::Mutex mutex_;
  std::map<std::string, Repeat, std::less<>> recent_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace cosmicd

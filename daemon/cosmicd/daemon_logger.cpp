#include "daemon_logger.hpp"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdlib>

namespace cosmicd {

cosmic::LogLevel parse_log_level(const std::string& text) {
  if (text == "debug") return cosmic::LogLevel::debug;
  if (text == "notice") return cosmic::LogLevel::notice;
  if (text == "warning") return cosmic::LogLevel::warning;
  if (text == "error") return cosmic::LogLevel::error;
  return cosmic::LogLevel::info;
}
namespace {

constexpr std::size_t kMaxTrackedMessages = 256;

// syslog priority of a level, as sd-daemon(3) prefixes expect ("<5>" for notice).
char syslog_priority(cosmic::LogLevel level) {
  switch (level) {
    case cosmic::LogLevel::debug:
      return '7';
    case cosmic::LogLevel::info:
      return '6';
    case cosmic::LogLevel::notice:
      return '5';
    case cosmic::LogLevel::warning:
      return '4';
    case cosmic::LogLevel::error:
      return '3';
  }
  return '6';
}

spdlog::level::level_enum to_spdlog(cosmic::LogLevel level) {
  switch (level) {
    case cosmic::LogLevel::debug:
      return spdlog::level::debug;
    case cosmic::LogLevel::info:
    case cosmic::LogLevel::notice:  // spdlog has no notice level
      return spdlog::level::info;
    case cosmic::LogLevel::warning:
      return spdlog::level::warn;
    case cosmic::LogLevel::error:
      return spdlog::level::err;
  }
  return spdlog::level::info;
}

}  // namespace

DaemonLogger::DaemonLogger(cosmic::LogLevel threshold, std::chrono::milliseconds repeat_window)
    : threshold_(threshold),
      repeat_window_(repeat_window),
      journald_(std::getenv("JOURNAL_STREAM") != nullptr),
      sink_(std::make_shared<spdlog::logger>("cosmicd", std::make_shared<spdlog::sinks::stderr_sink_mt>())) {
  // Under journald the prefix carries the priority and the journal adds the timestamp.
  sink_->set_pattern(journald_ ? "%v" : "%Y-%m-%d %H:%M:%S.%e %^%l%$ %v");
  sink_->set_level(spdlog::level::debug);
  sink_->flush_on(spdlog::level::debug);
}

void DaemonLogger::log(cosmic::LogLevel level, std::string_view message) {
  if (level < threshold_) return;
  const auto now = std::chrono::steady_clock::now();
  std::uint64_t folded = 0;
  {
    cosmic::LockGuard lock(mutex_);
    auto it = recent_.find(message);
    if (it != recent_.end() && now - it->second.window_start < repeat_window_) {
      ++it->second.suppressed;
      return;
    }
    if (it != recent_.end()) {
      folded = it->second.suppressed;
      it->second = Repeat{now, 0};
    } else {
      if (recent_.size() >= kMaxTrackedMessages) recent_.clear();
      recent_.emplace(std::string(message), Repeat{now, 0});
    }
  }
  const std::string prefix = journald_ ? std::string{'<', syslog_priority(level), '>'} : std::string();
  if (folded > 0) {
    sink_->log(to_spdlog(level), "{}{} (repeated {} more times)", prefix, message, folded);
  } else {
    sink_->log(to_spdlog(level), "{}{}", prefix, message);
  }
}

}  // namespace cosmicd

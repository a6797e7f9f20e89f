#include "daemon_logger.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdlib>

namespace cosmicd {
namespace {

constexpr std::size_t kMaxTrackedMessages = 256;

// "%*" in the pattern: the syslog priority of the level, as sd-daemon(3) prefixes expect.
class PriorityFlag final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
    int priority = 6;
    switch (msg.level) {
      case spdlog::level::trace:
      case spdlog::level::debug: priority = 7; break;
      case spdlog::level::info: priority = 6; break;
      case spdlog::level::warn: priority = 4; break;
      case spdlog::level::err: priority = 3; break;
      case spdlog::level::critical: priority = 2; break;
      default: priority = 5; break;
    }
    const char text[] = {'<', static_cast<char>('0' + priority), '>'};
    dest.append(text, text + 3);
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<PriorityFlag>(); }
};

spdlog::level::level_enum to_spdlog(cosmic::LogLevel level) {
  switch (level) {
    case cosmic::LogLevel::debug: return spdlog::level::debug;
    case cosmic::LogLevel::info: return spdlog::level::info;
    case cosmic::LogLevel::notice: return spdlog::level::info;
    case cosmic::LogLevel::warning: return spdlog::level::warn;
    case cosmic::LogLevel::error: return spdlog::level::err;
  }
  return spdlog::level::info;
}

}  // namespace

DaemonLogger::DaemonLogger(cosmic::LogLevel threshold, std::chrono::milliseconds repeat_window)
    : threshold_(threshold), repeat_window_(repeat_window), sink_(std::make_shared<spdlog::logger>("cosmicd", std::make_shared<spdlog::sinks::stderr_sink_mt>())) {
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  if (std::getenv("JOURNAL_STREAM") != nullptr) {
    formatter->add_flag<PriorityFlag>('*').set_pattern("%*%v");
  } else {
    formatter->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%l%$ %v");
  }
  sink_->set_formatter(std::move(formatter));
  sink_->set_level(spdlog::level::debug);
  sink_->flush_on(spdlog::level::debug);
}

void DaemonLogger::log(cosmic::LogLevel level, std::string_view message) {
  if (level < threshold_) return;
  const auto now = std::chrono::steady_clock::now();
  std::uint64_t folded = 0;
  {
    std::lock_guard lock(mutex_);
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
  if (folded > 0) sink_->log(to_spdlog(level), "{} (repeated {} more times)", message, folded);
  else sink_->log(to_spdlog(level), "{}", message);
}

}  // namespace cosmicd

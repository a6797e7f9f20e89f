// Helpers of the DDS integration tests: a child process with captured output, a recording
// EventSink and Logger, and waiting on conditions with a deadline (never fixed sleeps).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/log.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::test {

using Clock = std::chrono::steady_clock;
inline Clock::time_point deadline_in(std::chrono::milliseconds d) { return Clock::now() + d; }

// Polls `condition` every millisecond until it holds or the deadline passes.
bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds within);

// A child process whose stdout and stderr are collected line by line (stdin is a pipe).
class Child {
 public:
  explicit Child(std::vector<std::string> argv);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // Waits until some stdout (stderr) line satisfies `match`, or the deadline passes.
  bool wait_out(const std::function<bool(const std::string&)>& match, std::chrono::milliseconds within);
  bool wait_err(const std::function<bool(const std::string&)>& match, std::chrono::milliseconds within);
  // Exit status (exit code, or 128 + signal), nullopt if still running at the deadline.
  std::optional<int> wait_exit(std::chrono::milliseconds within);
  // Writes one line to the child's stdin.
  void send_line(const std::string& line);
  std::vector<std::string> out_lines() const;
  std::vector<std::string> err_lines() const;
  std::string describe() const;  // argv and stderr, for failure messages

 private:
  void pump(int fd, std::vector<std::string>& lines);
  bool wait_lines(const std::vector<std::string>& lines, const std::function<bool(const std::string&)>& match,
                  std::chrono::milliseconds within);

  std::vector<std::string> argv_;
  pid_t pid_ = -1;
  std::optional<int> status_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<std::string> out_;
  std::vector<std::string> err_;
  std::thread out_thread_;
  std::thread err_thread_;
  int stdin_fd_ = -1;
};

// Records what an adapter delivers (payloads copied).
class RecordingSink final : public EventSink {
 public:
  struct Event {
    ChannelId channel;
    EventHeader header;
    std::vector<std::uint8_t> payload;
    Nanos received_at;
    std::optional<ChannelClass> receiver_class;
  };
  void on_event(const InboundEvent& event) override;
  void on_problem(ChannelId channel, InboundProblem problem) override;

  std::vector<Event> events() const;
  std::vector<Event> events_on(ChannelId channel) const;
  std::size_t count_on(ChannelId channel) const;
  std::size_t problems(InboundProblem problem) const;
  using Problems = std::map<InboundProblem, std::size_t>;
  // Waits until `condition` (called with the recorder's lock held) holds.
  bool wait(const std::function<bool(const std::vector<Event>&, const Problems&)>& condition,
            std::chrono::milliseconds within);
  bool wait_count(ChannelId channel, std::size_t n, std::chrono::milliseconds within);
  bool wait_problems(InboundProblem problem, std::size_t n, std::chrono::milliseconds within);

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Event> events_;
  Problems problems_;
};

class StderrLogger final : public Logger {
 public:
  void log(LogLevel level, std::string_view message) override;

 private:
  std::mutex mutex_;
};

}  // namespace cosmic::test

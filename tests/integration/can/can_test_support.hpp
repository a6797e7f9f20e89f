// Helpers of the CAN integration tests: can-utils peers (candump -L capture with a readiness
// check, shell commands), a recording EventSink and logger, bindings as admission plans them.
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
#include <vector>

#include "cosmic/log.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::test {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Runs `command` with sh -c; returns its exit status (-1 if it did not exit normally).
int shell(const std::string& command);
// Runs `command` and returns its stdout.
std::string shell_output(const std::string& command);
// Polls `condition` every few milliseconds until it holds or `timeout` passes.
bool wait_until(const std::function<bool()>& condition, milliseconds timeout);
std::string hex(const std::vector<std::uint8_t>& bytes);
std::string hex_id(std::uint32_t id);  // 8 upper-case hex digits

// One line of `candump -L`.
struct CanLine {
  std::string interface;
  std::uint32_t id = 0;  // without flags
  bool extended = false;
  bool fd = false;
  std::uint8_t fd_flags = 0;
  bool rtr = false;
  std::vector<std::uint8_t> data;
};
std::optional<CanLine> parse_candump_line(const std::string& line);

// Raw CAN receivers (filter entries) registered on `interface` (/proc/net/can/rcvlist_*).
int raw_receivers(const std::string& interface);

// `candump -L -n COUNT SPEC` in the background, its output in a temp file. The constructor
// returns once candump's socket is registered in the kernel (or throws after 10 s).
class Candump {
 public:
  Candump(const std::string& interface, const std::string& spec, int count);
  ~Candump();
  Candump(const Candump&) = delete;
  Candump& operator=(const Candump&) = delete;
  // Waits until candump has printed `count` frames and exited (or the timeout passes, then it is
  // killed); returns the frames it printed.
  std::vector<CanLine> wait(milliseconds timeout);
  // Frames printed so far.
  std::vector<CanLine> lines() const;

 private:
  std::string file_;
  pid_t pid_ = -1;
};

struct ReceivedEvent {
  ChannelId channel = kNoChannel;
  std::uint64_t subject = 0;
  std::vector<std::uint8_t> payload;
};

class RecordingSink final : public EventSink {
 public:
  void on_event(const InboundEvent& event) override;
  void on_problem(ChannelId channel, InboundProblem problem) override;

  std::vector<ReceivedEvent> events() const;
  std::size_t event_count() const;
  std::size_t problem_count() const;
  std::size_t problem_count(InboundProblem problem) const;
  bool wait_events(std::size_t count, milliseconds timeout) const;
  bool wait_problems(std::size_t count, milliseconds timeout) const;
  // While blocked, on_event waits (the adapter's receive thread stalls).
  void block(bool blocked);

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::vector<ReceivedEvent> events_;
  std::map<InboundProblem, std::size_t> problems_;
  bool blocked_ = false;
};

class RecordingLogger final : public Logger {
 public:
  void log(LogLevel level, std::string_view message) override;
  std::vector<std::string> messages() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

inline constexpr std::uint8_t kGatewayNode = 1;
inline constexpr std::uint8_t kDeviceNode = 5;

SegmentSpec can_segment(const std::string& interface, bool fd = false);
// A binding as admission plans it: identifier = priority | gateway TxNode | etag.
ChannelBinding can_binding(ChannelId id, const std::string& name, std::uint64_t subject, std::uint64_t payload,
                           HopRole role, std::uint8_t priority, std::uint16_t etag, const SegmentSpec& segment);

}  // namespace cosmic::test

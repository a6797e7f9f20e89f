// Helpers shared by the LCM adapter integration tests (lcm_adapter_test.cpp,
// lcm_adapter_reconfig_test.cpp): a child process with captured output (cosmic-lcm-peer,
// lcm-logger), a recording EventSink and Logger, channel and event builders, the LcmAdapterTest
// fixture (which insists on scripts/netns-run), a reader of lcm-logger's log files and polling
// with a deadline.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/build_paths.hpp"
#include "cosmic/lcm_adapter.hpp"

namespace cosmic::lcm_test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;

inline constexpr auto kWait = 15s;

inline std::string url_for(int port) { return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0"; }

// Payload byte i of message k as cosmic-lcm-peer pub writes it.
inline Bytes peer_pattern(std::uint64_t k, std::size_t size) {
  Bytes b(size);
  for (std::size_t i = 0; i < size; ++i) b[i] = static_cast<std::uint8_t>((k * 31 + i) & 0xff);
  return b;
}

// Distinct test content of our own.
inline Bytes own_pattern(std::uint32_t k, std::size_t size) {
  Bytes b;
  b.reserve(size);
  // push_back rather than indexing: GCC 12 at -O3 (build-bench) takes b[i] of a constant size
  // inlined from a test for a write out of bounds (-Wstringop-overflow).
  for (std::size_t i = 0; i < size; ++i) b.push_back(static_cast<std::uint8_t>((k * 7 + i * 13 + 5) & 0xff));
  if (size >= 4) {
    b[0] = static_cast<std::uint8_t>(k >> 24);
    b[1] = static_cast<std::uint8_t>(k >> 16);
    b[2] = static_cast<std::uint8_t>(k >> 8);
    b[3] = static_cast<std::uint8_t>(k);
  }
  return b;
}

inline std::string hex(const Bytes& b) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto v : b) {
    out.push_back(digits[v >> 4]);
    out.push_back(digits[v & 0xf]);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// A child process with its stdout and stderr captured.
class Child {
 public:
  explicit Child(std::vector<std::string> argv) {
    int out[2];
    int err[2];
    if (pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0) throw std::runtime_error("pipe2");
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork");
    if (pid_ == 0) {
      dup2(out[1], STDOUT_FILENO);
      dup2(err[1], STDERR_FILENO);
      std::vector<char*> args;
      for (auto& a : argv) args.push_back(a.data());
      args.push_back(nullptr);
      execv(args[0], args.data());
      std::perror("execv");
      _exit(127);
    }
    close(out[1]);
    close(err[1]);
    out_fd_ = out[0];
    err_fd_ = err[0];
    fcntl(out_fd_, F_SETFL, O_NONBLOCK);
    fcntl(err_fd_, F_SETFL, O_NONBLOCK);
  }

  ~Child() {
    if (!exit_status_) {
      kill(pid_, SIGKILL);
      int status = 0;
      waitpid(pid_, &status, 0);
    }
    if (out_fd_ >= 0) close(out_fd_);
    if (err_fd_ >= 0) close(err_fd_);
  }

  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // Waits until a stderr line contains `needle` (e.g. READY).
  bool wait_stderr(const std::string& needle, Clock::duration timeout = kWait) {
    const auto deadline = Clock::now() + timeout;
    while (err_.find(needle) == std::string::npos) {
      if (Clock::now() >= deadline || exit_status_) return err_.find(needle) != std::string::npos;
      pump(50ms);
      reap();
    }
    return true;
  }

  // Waits until stdout holds `n` complete lines.
  bool wait_stdout_lines(std::size_t n, Clock::duration timeout = kWait) {
    const auto deadline = Clock::now() + timeout;
    while (static_cast<std::size_t>(std::count(out_.begin(), out_.end(), '\n')) < n) {
      if (Clock::now() >= deadline || exit_status_) return false;
      pump(50ms);
      reap();
    }
    return true;
  }

  // Waits for the process to exit; its exit code, or nullopt on timeout / signal.
  std::optional<int> wait_exit(Clock::duration timeout = kWait) {
    const auto deadline = Clock::now() + timeout;
    while (!exit_status_ && Clock::now() < deadline) {
      pump(50ms);
      reap();
    }
    if (!exit_status_) return std::nullopt;
    while (pump(0ms)) {
    }
    if (!WIFEXITED(*exit_status_)) return std::nullopt;
    return WEXITSTATUS(*exit_status_);
  }

  void signal(int sig) { kill(pid_, sig); }

  std::vector<std::string> stdout_lines() const {
    std::vector<std::string> lines;
    std::istringstream in(out_);
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) lines.push_back(line);
    return lines;
  }
  const std::string& stderr_text() const { return err_; }

 private:
  // Reads what is available; true if anything was read.
  bool pump(std::chrono::milliseconds timeout) {
    pollfd fds[2] = {{out_fd_, POLLIN, 0}, {err_fd_, POLLIN, 0}};
    if (poll(fds, 2, static_cast<int>(timeout.count())) <= 0) return false;
    bool any = false;
    char buf[65536];
    for (auto [fd, target] : {std::pair{out_fd_, &out_}, std::pair{err_fd_, &err_}}) {
      for (;;) {
        const ssize_t n = read(fd, buf, sizeof buf);
        if (n <= 0) break;
        target->append(buf, static_cast<std::size_t>(n));
        any = true;
      }
    }
    return any;
  }

  void reap() {
    if (exit_status_) return;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) exit_status_ = status;
  }

  pid_t pid_ = -1;
  int out_fd_ = -1;
  int err_fd_ = -1;
  std::string out_;
  std::string err_;
  std::optional<int> exit_status_;
};

// ---------------------------------------------------------------------------------------------
class RecordingSink final : public EventSink {
 public:
  struct Record {
    ChannelId channel;
    EventHeader header;
    Bytes payload;
    bool fingerprint_guard = false;  // InboundEvent::identity.needs_fingerprint_loop_guard()
  };

  void on_event(const InboundEvent& event) override {
    std::lock_guard lock(mutex_);
    events_.push_back({event.channel, event.header, Bytes(event.payload.begin(), event.payload.end()),
                       event.identity.needs_fingerprint_loop_guard()});
    changed_.notify_all();
  }
  void on_problem(ChannelId channel, InboundProblem problem) override {
    std::lock_guard lock(mutex_);
    ++problems_[{channel, problem}];
    changed_.notify_all();
  }

  std::size_t count_unlocked(ChannelId channel) const {
    return static_cast<std::size_t>(
        std::count_if(events_.begin(), events_.end(), [&](const Record& r) { return r.channel == channel; }));
  }
  std::size_t problems_unlocked(ChannelId channel, InboundProblem problem) const {
    auto it = problems_.find({channel, problem});
    return it == problems_.end() ? 0 : it->second;
  }

  bool wait_events(ChannelId channel, std::size_t n, Clock::duration timeout = kWait) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return count_unlocked(channel) >= n; });
  }
  bool wait_problems(ChannelId channel, InboundProblem problem, std::size_t n, Clock::duration timeout = kWait) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return problems_unlocked(channel, problem) >= n; });
  }

  std::size_t count(ChannelId channel) const {
    std::lock_guard lock(mutex_);
    return count_unlocked(channel);
  }
  std::size_t problems(ChannelId channel, InboundProblem problem) const {
    std::lock_guard lock(mutex_);
    return problems_unlocked(channel, problem);
  }
  std::vector<Record> events(ChannelId channel) const {
    std::lock_guard lock(mutex_);
    std::vector<Record> out;
    for (const auto& r : events_)
      if (r.channel == channel) out.push_back(r);
    return out;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Record> events_;
  std::map<std::pair<ChannelId, InboundProblem>, std::size_t> problems_;
};

class TestLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override {
    std::lock_guard lock(mutex_);
    lines_.emplace_back(message);
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

inline ChannelBinding binding(ChannelId id, const std::string& name, HopRole role,
                              LcmEncoding encoding = LcmEncoding::envelope, std::uint64_t subject = 0) {
  ChannelBinding b;
  b.id = id;
  b.spec.name = name;
  b.spec.subject = subject;
  b.spec.lcm_encoding = encoding;
  b.spec.payload = 65000;
  b.role = role;
  return b;
}

inline OutboundEvent outbound(ChannelId channel, const Bytes& payload, std::uint32_t sequence = 0,
                              std::uint64_t subject = 0, std::uint64_t origin = 0) {
  OutboundEvent e;
  e.channel = channel;
  e.header.subject = subject;
  e.header.origin = origin;
  e.header.sequence = sequence;
  e.header.hop_count = 1;
  e.header.created_ns = 123456789;
  e.header.age_ns = 1000 * static_cast<std::int64_t>(sequence);
  e.payload = payload;
  return e;
}

inline std::string peer() { return cosmic::build_paths::lcm_peer; }

// The drops the kernel counted for the UDP socket bound to `port` (the last column of
// /proc/net/udp); 0 when there is none.
inline std::uint64_t udp_socket_drops(int port) {
  std::ifstream table("/proc/net/udp");
  std::string line;
  std::getline(table, line);  // the header
  char wanted[8];
  std::snprintf(wanted, sizeof wanted, ":%04X ", port);
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, local, last, field;
    fields >> slot >> local;
    if ((local + " ").find(wanted) == std::string::npos) continue;
    while (fields >> field) last = field;
    return std::stoull(last);
  }
  return 0;
}

class LcmAdapterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* in_netns = std::getenv("COSMIC_IN_NETNS");
    if (in_netns == nullptr || std::string(in_netns) != "1")
      GTEST_FAIL() << "run these tests through scripts/netns-run (multicast must stay on loopback)";
  }

  std::unique_ptr<SegmentAdapter> make(int port, const std::string& name = "lcm0") {
    segment_.name = name;
    segment_.type = SegmentType::lcm;
    segment_.lcm.url = url_for(port);
    return make_lcm_adapter(segment_, self_, logger_);
  }

  SegmentSpec segment_;
  GatewayIdentity self_{0x1234'5678'9abc'def0ULL, "gw-test"};
  TestLogger logger_;
  RecordingSink sink_;
};

// ---------------------------------------------------------------------------------------------
// LCM log file (lcm-logger): events of
//   u32 sync 0xEDA1DA01, i64 event number, i64 timestamp (us), i32 channel length,
//   i32 data length, channel bytes, data bytes; all big-endian.
struct LogEvent {
  std::string channel;
  Bytes data;
};

inline std::vector<LogEvent> read_lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto be = [&](std::size_t at, int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | static_cast<std::uint8_t>(file[at + i]);
    return v;
  };
  std::vector<LogEvent> events;
  std::size_t pos = 0;
  constexpr std::size_t kHeader = 4 + 8 + 8 + 4 + 4;
  while (pos + kHeader <= file.size()) {
    if (be(pos, 4) != 0xEDA1DA01) break;
    const std::size_t channel_len = be(pos + 20, 4);
    const std::size_t data_len = be(pos + 24, 4);
    if (pos + kHeader + channel_len + data_len > file.size()) break;  // still being written
    LogEvent e;
    e.channel = file.substr(pos + kHeader, channel_len);
    const auto* data = reinterpret_cast<const std::uint8_t*>(file.data() + pos + kHeader + channel_len);
    e.data.assign(data, data + data_len);
    events.push_back(std::move(e));
    pos += kHeader + channel_len + data_len;
  }
  return events;
}

inline std::size_t count_channel(const std::vector<LogEvent>& events, const std::string& channel) {
  return static_cast<std::size_t>(
      std::count_if(events.begin(), events.end(), [&](const LogEvent& e) { return e.channel == channel; }));
}

// Polls `condition` (e.g. a file another process writes) until it holds or the time is up.
inline bool poll_until(const std::function<bool()>& condition, Clock::duration timeout = kWait,
                       const std::function<void()>& between = {}) {
  const auto deadline = Clock::now() + timeout;
  while (!condition()) {
    if (Clock::now() >= deadline) return false;
    if (between) between();
    std::this_thread::sleep_for(20ms);
  }
  return true;
}

}  // namespace cosmic::lcm_test

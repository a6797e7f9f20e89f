// LCM segment adapter against real LCM peers in separate processes: cosmic-lcm-peer and the
// stock lcm-logger. Each test runs in its own network namespace (scripts/netns-run, multicast on
// loopback only) and uses its own multicast port. Tests wait on conditions, never on fixed sleeps.
#include <fcntl.h>
#include <lcm/lcm.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/envelope.hpp"
#include "cosmic/lcm_adapter.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/transport_limits.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;

constexpr auto kWait = 15s;

std::string url_for(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

// Payload byte i of message k as cosmic-lcm-peer pub writes it.
Bytes peer_pattern(std::uint64_t k, std::size_t size) {
  Bytes b(size);
  for (std::size_t i = 0; i < size; ++i) b[i] = static_cast<std::uint8_t>((k * 31 + i) & 0xff);
  return b;
}

// Distinct test content of our own.
Bytes own_pattern(std::uint32_t k, std::size_t size) {
  Bytes b(size);
  for (std::size_t i = 0; i < size; ++i) b[i] = static_cast<std::uint8_t>((k * 7 + i * 13 + 5) & 0xff);
  if (size >= 4) {
    b[0] = static_cast<std::uint8_t>(k >> 24);
    b[1] = static_cast<std::uint8_t>(k >> 16);
    b[2] = static_cast<std::uint8_t>(k >> 8);
    b[3] = static_cast<std::uint8_t>(k);
  }
  return b;
}

std::string hex(const Bytes& b) {
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
    bool fingerprint_guard = false;  // InboundEvent::guard_loops_by_fingerprint
  };

  void on_event(const InboundEvent& event) override {
    std::lock_guard lock(mutex_);
    events_.push_back({event.channel, event.header, Bytes(event.payload.begin(), event.payload.end()), event.guard_loops_by_fingerprint});
    changed_.notify_all();
  }
  void on_problem(ChannelId channel, InboundProblem problem) override {
    std::lock_guard lock(mutex_);
    ++problems_[{channel, problem}];
    changed_.notify_all();
  }

  std::size_t count_unlocked(ChannelId channel) const {
    return static_cast<std::size_t>(std::count_if(
        events_.begin(), events_.end(), [&](const Record& r) { return r.channel == channel; }));
  }
  std::size_t problems_unlocked(ChannelId channel, InboundProblem problem) const {
    auto it = problems_.find({channel, problem});
    return it == problems_.end() ? 0 : it->second;
  }

  bool wait_events(ChannelId channel, std::size_t n, Clock::duration timeout = kWait) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return count_unlocked(channel) >= n; });
  }
  bool wait_problems(ChannelId channel, InboundProblem problem, std::size_t n,
                     Clock::duration timeout = kWait) {
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

ChannelBinding binding(ChannelId id, const std::string& name, HopRole role,
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

OutboundEvent outbound(ChannelId channel, const Bytes& payload, std::uint32_t sequence = 0,
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

std::string peer() { return COSMIC_LCM_PEER; }

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

std::vector<LogEvent> read_lcm_log(const std::string& path) {
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

std::size_t count_channel(const std::vector<LogEvent>& events, const std::string& channel) {
  return static_cast<std::size_t>(std::count_if(
      events.begin(), events.end(), [&](const LogEvent& e) { return e.channel == channel; }));
}

// Polls `condition` (e.g. a file another process writes) until it holds or the time is up.
bool poll_until(const std::function<bool()>& condition, Clock::duration timeout = kWait,
                const std::function<void()>& between = {}) {
  const auto deadline = Clock::now() + timeout;
  while (!condition()) {
    if (Clock::now() >= deadline) return false;
    if (between) between();
    std::this_thread::sleep_for(20ms);
  }
  return true;
}

// ---------------------------------------------------------------------------------------------

TEST_F(LcmAdapterTest, HealthAndBadUrl) {
  auto adapter = make(7700);
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  adapter->stop();  // stop before start is harmless

  segment_.lcm.url = "nosuchprovider://x";
  auto bad = make_lcm_adapter(segment_, self_, logger_);
  const std::vector<ChannelBinding> bindings{binding(1, "CH", HopRole::publisher)};
  EXPECT_TRUE(bad->configure(bindings).ok);
  const Status st = bad->start(sink_);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.error.find("nosuchprovider://x"), std::string::npos) << st.error;
  EXPECT_EQ(bad->health().state, SegmentHealth::down);
  EXPECT_NE(bad->health().detail.find("lcm_create failed"), std::string::npos);
  EXPECT_EQ(bad->send(outbound(1, Bytes{1, 2})), SendStatus::failed);
  bad->stop();
  bad->stop();

  ASSERT_TRUE(adapter->start(sink_).ok);
  EXPECT_EQ(adapter->health().state, SegmentHealth::up);
  EXPECT_FALSE(adapter->start(sink_).ok);  // already started
  adapter->stop();
  adapter->stop();
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
}

TEST_F(LcmAdapterTest, PeerSubscriberTimesOutWithoutMessages) {
  Child sub({peer(), "sub", "--url", url_for(7701), "--channel", "NOBODY", "--count", "1",
             "--timeout", "0.3"});
  ASSERT_TRUE(sub.wait_stderr("READY"));
  const auto code = sub.wait_exit();
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
}

TEST_F(LcmAdapterTest, EnvelopeToNativeSubscriber) {
  const int port = 7702;
  constexpr int kCount = 40;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(7, "COSMIC_ENV", HopRole::subscriber)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  Child sub({peer(), "sub", "--url", url_for(port), "--channel", "COSMIC_ENV", "--count",
             std::to_string(kCount), "--timeout", "10"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();

  for (std::uint32_t k = 1; k <= kCount; ++k) {
    const Bytes payload = own_pattern(k, 8 + k);
    // Odd events originate here (origin 0: the adapter stamps its own id), even ones elsewhere.
    const std::uint64_t origin = (k % 2 == 1) ? 0 : 777;
    ASSERT_EQ(adapter->send(outbound(7, payload, k, 0xC0FFEE, origin)), SendStatus::sent);
  }
  const auto code = sub.wait_exit();
  ASSERT_EQ(code, std::optional<int>(0)) << sub.stderr_text();
  const auto lines = sub.stdout_lines();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t k = 1; k <= kCount; ++k) {
    const auto j = nlohmann::json::parse(lines[k - 1]);
    EXPECT_EQ(j["channel"], "COSMIC_ENV");
    EXPECT_EQ(j["sequence"].get<std::uint32_t>(), k);
    EXPECT_EQ(j["subject"].get<std::uint64_t>(), 0xC0FFEEu);
    EXPECT_EQ(j["origin"].get<std::uint64_t>(), (k % 2 == 1) ? self_.id : 777u);
    EXPECT_EQ(j["hop_count"].get<int>(), 1);
    EXPECT_EQ(j["age_ns"].get<std::int64_t>(), 1000 * static_cast<std::int64_t>(k));
    EXPECT_EQ(j["created_ns"].get<std::int64_t>(), 123456789);
    EXPECT_EQ(j["payload"].get<std::string>(), hex(own_pattern(k, 8 + k)));
  }
  EXPECT_EQ(adapter->statistics().sent, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(adapter->statistics().send_errors, 0u);
  // Not bound for sending: refused.
  EXPECT_EQ(adapter->send(outbound(99, Bytes{1})), SendStatus::failed);
  adapter->stop();
}

TEST_F(LcmAdapterTest, RawFromNativePublisherKeepsBytes) {
  const int port = 7703;
  constexpr int kCount = 60;
  constexpr std::size_t kSize = 64;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{
      binding(3, "NATIVE_POSE", HopRole::publisher, LcmEncoding::raw, 4242)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);  // subscribed (group joined) when start returns

  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "NATIVE_POSE", "--raw", "--count",
             std::to_string(kCount), "--size", std::to_string(kSize), "--rate", "2000"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(3, kCount)) << sink_.count(3);

  const auto events = sink_.events(3);
  ASSERT_EQ(events.size(), static_cast<std::size_t>(kCount));
  for (std::size_t i = 0; i < events.size(); ++i) {
    const auto& e = events[i];
    EXPECT_EQ(e.payload, peer_pattern(i + 1, kSize)) << "message " << i + 1;
    EXPECT_EQ(e.header.subject, 4242u);
    EXPECT_EQ(e.header.origin, 0u);
    EXPECT_EQ(e.header.sequence, 0u);
    EXPECT_EQ(e.header.age_ns, 0);
    EXPECT_EQ(e.header.hop_count, 0);
  }
  EXPECT_EQ(adapter->statistics().received, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(sink_.problems(3, InboundProblem::own_echo), 0u);
  adapter->stop();
}

// A native binding (issue 19, item 5) names the LCM channel; the contents travel raw, and the router
// is told to guard loops by fingerprint (raw messages carry no origin).
TEST_F(LcmAdapterTest, ANativeBindingNamesTheLcmChannelAndCarriesTheContentsRaw) {
  const int port = 7711;
  auto adapter = make(port);
  ChannelBinding wheel = binding(9, "wheel", HopRole::publisher, LcmEncoding::envelope, 0x90);
  wheel.spec.native.push_back(NativeBinding{"lcm0", std::nullopt, "WHEEL_SPEED", std::nullopt});
  ASSERT_TRUE(adapter->configure(std::vector<ChannelBinding>{wheel}).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "WHEEL_SPEED", "--raw", "--count", "5", "--size", "8", "--rate", "1000"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(9, 5)) << sink_.count(9);
  const auto events = sink_.events(9);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 8)) << "message " << i + 1;
    EXPECT_EQ(events[i].header.subject, 0x90u);
    EXPECT_TRUE(events[i].fingerprint_guard);
  }
  // Nothing is read on the channel's own name.
  Child other({peer(), "pub", "--url", url_for(port), "--channel", "wheel", "--raw", "--count", "3", "--size", "8"});
  ASSERT_EQ(other.wait_exit(), std::optional<int>(0)) << other.stderr_text();
  Child marker({peer(), "pub", "--url", url_for(port), "--channel", "WHEEL_SPEED", "--raw", "--count", "1", "--size", "4"});
  ASSERT_EQ(marker.wait_exit(), std::optional<int>(0)) << marker.stderr_text();
  ASSERT_TRUE(sink_.wait_events(9, 6)) << sink_.count(9);
  EXPECT_EQ(sink_.count(9), 6u);  // the marker after the three on "wheel": those were never delivered
  adapter->stop();
}

TEST_F(LcmAdapterTest, RestartResubscribes) {
  const int port = 7709;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{
      binding(4, "AGAIN", HopRole::publisher, LcmEncoding::raw, 1)};
  ASSERT_TRUE(adapter->start(sink_).ok);  // configured after start
  ASSERT_TRUE(adapter->configure(bindings).ok);
  adapter->stop();
  ASSERT_TRUE(adapter->start(sink_).ok);  // the channel table survives stop()
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "AGAIN", "--raw", "--count", "3",
             "--size", "4"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(4, 3));
  EXPECT_EQ(adapter->health().state, SegmentHealth::up);
  adapter.reset();  // the destructor stops
}

TEST_F(LcmAdapterTest, RawSendIsRecordedByLcmLogger) {
  const int port = 7704;
  const std::string url = url_for(port);
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{
      binding(1, "RAW_SCAN", HopRole::subscriber, LcmEncoding::raw),
      binding(2, "COSMIC_PROBE", HopRole::subscriber, LcmEncoding::raw)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  char dir_template[] = "/tmp/cosmic-lcm-log-XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  struct RemoveDir {
    std::string path;
    ~RemoveDir() { std::filesystem::remove_all(path); }
  } remove_dir{dir_template};
  const std::string log_path = std::string(dir_template) + "/scan.lcmlog";

  Child logger({COSMIC_LCM_LOGGER, "-q", "-f", "--flush-interval=10", "--lcm-url=" + url, log_path});
  // lcm-logger has no readiness signal: publish probes until one shows up in its file.
  const Bytes probe{0x50, 0x52, 0x4f, 0x42, 0x45};
  ASSERT_TRUE(poll_until([&] { return count_channel(read_lcm_log(log_path), "COSMIC_PROBE") > 0; },
                         kWait, [&] { adapter->send(outbound(2, probe)); }))
      << logger.stderr_text();

  // Sizes from 1 byte to a fragmented 20 kB message.
  std::vector<Bytes> sent;
  const std::size_t sizes[] = {1, 8, 64, 200, 1400, 1500, 20000};
  for (std::uint32_t k = 1; k <= 35; ++k) sent.push_back(own_pattern(k, sizes[k % 7]));
  // One at a time, each once logged: a burst of 20 kB datagrams can overrun the logger's
  // receive buffers, which is LCM's business, not the adapter's. lcm-logger flushes its file
  // only when it writes an event, so probes keep nudging it until the message shows up.
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_EQ(adapter->send(outbound(1, sent[i])), SendStatus::sent);
    ASSERT_TRUE(poll_until([&] { return count_channel(read_lcm_log(log_path), "RAW_SCAN") > i; },
                           kWait, [&] { adapter->send(outbound(2, probe)); }))
        << "message " << i << " not logged; " << logger.stderr_text();
  }
  logger.signal(SIGINT);
  ASSERT_TRUE(logger.wait_exit().has_value()) << logger.stderr_text();

  std::vector<Bytes> logged;
  for (const auto& e : read_lcm_log(log_path))
    if (e.channel == "RAW_SCAN") logged.push_back(e.data);
  EXPECT_EQ(logged, sent);
  adapter->stop();
}

TEST_F(LcmAdapterTest, OwnEnvelopesAreNotReceivedBack) {
  const int port = 7705;
  auto adapter = make(port);
  // The same channel received and sent on this segment: LCM loops our publications back.
  const std::vector<ChannelBinding> bindings{binding(5, "LOOPED", HopRole::publisher),
                                             binding(5, "LOOPED", HopRole::subscriber)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  for (std::uint32_t k = 1; k <= 10; ++k)
    ASSERT_EQ(adapter->send(outbound(5, own_pattern(k, 16), k)), SendStatus::sent);
  ASSERT_TRUE(sink_.wait_problems(5, InboundProblem::own_echo, 10))
      << sink_.problems(5, InboundProblem::own_echo) << " echoes, " << sink_.count(5) << " events, "
      << adapter->statistics().received << " received";

  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "LOOPED", "--count", "5", "--size",
             "16", "--origin", "5", "--subject", "9"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(5, 5));

  const auto events = sink_.events(5);
  ASSERT_EQ(events.size(), 5u);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].header.origin, 5u);
    EXPECT_EQ(events[i].header.subject, 9u);
    EXPECT_EQ(events[i].header.sequence, i + 1);
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 16));
  }
  EXPECT_EQ(sink_.problems(5, InboundProblem::own_echo), 10u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, OwnRawMessagesAreNotReceivedBack) {
  const int port = 7706;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{
      binding(6, "LOOPED_RAW", HopRole::publisher, LcmEncoding::raw, 11),
      binding(6, "LOOPED_RAW", HopRole::subscriber, LcmEncoding::raw, 11)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  for (std::uint32_t k = 1; k <= 10; ++k)
    ASSERT_EQ(adapter->send(outbound(6, own_pattern(k, 24))), SendStatus::sent);
  ASSERT_TRUE(sink_.wait_problems(6, InboundProblem::own_echo, 10))
      << sink_.problems(6, InboundProblem::own_echo) << " echoes, " << sink_.count(6) << " events, "
      << adapter->statistics().received << " received";

  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "LOOPED_RAW", "--raw", "--count",
             "5", "--size", "24"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(6, 5));

  const auto events = sink_.events(6);
  ASSERT_EQ(events.size(), 5u);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 24));
    EXPECT_EQ(events[i].header.subject, 11u);
  }
  EXPECT_EQ(sink_.problems(6, InboundProblem::own_echo), 10u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, ConfigureWhileFlowingLosesNothingOnOtherChannels) {
  const int port = 7707;
  const std::string url = url_for(port);
  constexpr int kCount = 250;  // peer payloads stay distinct below 256 messages
  auto adapter = make(port);
  const ChannelBinding a = binding(1, "FLOW_IN", HopRole::publisher, LcmEncoding::raw);
  const ChannelBinding t = binding(2, "FLOW_OUT", HopRole::subscriber);
  const ChannelBinding b = binding(3, "EXTRA_IN", HopRole::publisher, LcmEncoding::raw);
  const ChannelBinding c = binding(4, "EXTRA_OUT", HopRole::subscriber);
  const std::vector<std::vector<ChannelBinding>> configs{{a, t}, {a, t, b}, {t, a, c}, {a, t, b, c}};
  ASSERT_TRUE(adapter->configure(configs[0]).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  Child sub({peer(), "sub", "--url", url, "--channel", "FLOW_OUT", "--count",
             std::to_string(kCount), "--timeout", "20"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();
  Child pub({peer(), "pub", "--url", url, "--channel", "FLOW_IN", "--raw", "--count",
             std::to_string(kCount), "--size", "16", "--rate", "250"});

  // Send on FLOW_OUT and reconfigure the segment over and over while FLOW_IN flows in.
  std::uint32_t sent = 0;
  std::size_t reconfigurations = 0;
  const auto deadline = Clock::now() + 20s;
  while ((sent < kCount || sink_.count(1) < kCount) && Clock::now() < deadline) {
    if (sent < kCount) {
      ++sent;
      ASSERT_EQ(adapter->send(outbound(2, own_pattern(sent, 16), sent)), SendStatus::sent);
    }
    ASSERT_TRUE(adapter->configure(configs[reconfigurations % configs.size()]).ok);
    ++reconfigurations;
    std::this_thread::sleep_for(2ms);  // pacing only
  }
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(1, kCount)) << sink_.count(1);
  EXPECT_GT(reconfigurations, 100u);

  const auto in = sink_.events(1);
  ASSERT_EQ(in.size(), static_cast<std::size_t>(kCount));
  for (std::size_t i = 0; i < in.size(); ++i) EXPECT_EQ(in[i].payload, peer_pattern(i + 1, 16));

  ASSERT_EQ(sub.wait_exit(), std::optional<int>(0)) << sub.stderr_text();
  const auto lines = sub.stdout_lines();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t k = 1; k <= kCount; ++k)
    EXPECT_EQ(nlohmann::json::parse(lines[k - 1])["sequence"].get<std::uint32_t>(), k);

  // An added channel receives; a removed one no longer does.
  ASSERT_TRUE(adapter->configure(configs[1]).ok);
  {
    Child extra({peer(), "pub", "--url", url, "--channel", "EXTRA_IN", "--raw", "--count", "3",
                 "--size", "8"});
    ASSERT_EQ(extra.wait_exit(), std::optional<int>(0));
  }
  ASSERT_TRUE(sink_.wait_events(3, 3));
  const std::size_t extra_before = sink_.count(3);
  ASSERT_TRUE(adapter->configure(configs[0]).ok);
  {
    Child extra({peer(), "pub", "--url", url, "--channel", "EXTRA_IN", "--raw", "--count", "3",
                 "--size", "8"});
    ASSERT_EQ(extra.wait_exit(), std::optional<int>(0));
  }
  // A later message on FLOW_IN marks that the EXTRA_IN ones had their chance to arrive.
  {
    Child marker({peer(), "pub", "--url", url, "--channel", "FLOW_IN", "--raw", "--count", "1",
                  "--size", "16"});
    ASSERT_EQ(marker.wait_exit(), std::optional<int>(0));
  }
  ASSERT_TRUE(sink_.wait_events(1, kCount + 1));
  EXPECT_EQ(sink_.count(3), extra_before);
  EXPECT_EQ(adapter->statistics().sent, static_cast<std::uint64_t>(kCount));
  adapter->stop();
}

TEST_F(LcmAdapterTest, MalformedEnvelopesCountDecodeErrors) {
  const int port = 7708;
  const std::string url = url_for(port);
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(8, "ENV_IN", HopRole::publisher)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->start(sink_).ok);

  // A valid envelope, then damaged copies of it.
  ::cosmic::envelope e{};
  e.subject = 77;
  e.origin = 42;
  e.sequence = 1;
  e.hop_count = 1;
  e.created_ns = 1;
  e.age_ns = 2;
  e.payload = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  e.payload_size = 10;
  Bytes valid(static_cast<std::size_t>(e.getEncodedSize()));
  ASSERT_EQ(e.encode(valid.data(), 0, static_cast<int>(valid.size())), static_cast<int>(valid.size()));
  auto with_payload_size = [&](std::uint32_t v) {
    Bytes b = valid;
    b[45] = static_cast<std::uint8_t>(v >> 24);
    b[46] = static_cast<std::uint8_t>(v >> 16);
    b[47] = static_cast<std::uint8_t>(v >> 8);
    b[48] = static_cast<std::uint8_t>(v);
    return b;
  };
  std::vector<Bytes> bad;
  bad.push_back(Bytes{1, 2, 3, 4, 5, 6, 7, 8, 9, 10});  // not an envelope at all
  Bytes wrong_hash = valid;
  wrong_hash[0] ^= 0xff;
  bad.push_back(wrong_hash);
  bad.push_back(with_payload_size(static_cast<std::uint32_t>(-5)));  // negative size
  bad.push_back(with_payload_size(100));                              // truncated payload
  bad.push_back(with_payload_size(0x7fffffff));                       // beyond max_message_size
  Bytes trailing = valid;
  trailing.push_back(0);
  bad.push_back(trailing);

  lcm_t* publisher = lcm_create(url.c_str());
  ASSERT_NE(publisher, nullptr);
  for (const auto& b : bad)
    ASSERT_EQ(lcm_publish(publisher, "ENV_IN", b.data(), static_cast<unsigned>(b.size())), 0);
  ASSERT_EQ(lcm_publish(publisher, "ENV_IN", valid.data(), static_cast<unsigned>(valid.size())), 0);
  lcm_destroy(publisher);

  ASSERT_TRUE(sink_.wait_events(8, 1));
  ASSERT_TRUE(sink_.wait_problems(8, InboundProblem::decode_error, bad.size()));
  EXPECT_EQ(sink_.problems(8, InboundProblem::decode_error), bad.size());
  EXPECT_EQ(adapter->statistics().receive_errors, bad.size());
  const auto events = sink_.events(8);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].header.subject, 77u);
  EXPECT_EQ(events[0].header.origin, 42u);
  EXPECT_EQ(events[0].payload, e.payload);

  // A native envelope publisher that is not us still gets through afterwards.
  Child pub({peer(), "pub", "--url", url, "--channel", "ENV_IN", "--count", "2", "--size", "0",
             "--origin", "99"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(8, 3));
  EXPECT_TRUE(sink_.events(8)[2].payload.empty());
  adapter->stop();
}

// Issue 9, item 10: the LCM name limit comes from cosmic/transport_limits.hpp (what the
// configuration checks), and a refused name is reported for its channel (Status::refused) while
// the segment carries the rest.
TEST_F(LcmAdapterTest, ANameBeyondTheTransportLimitIsRefusedForItsChannelAlone) {
  auto adapter = make(7710);
  const std::string longest(kLcmMaxChannelName, 'a');
  const std::string too_long(kLcmMaxChannelName + 1, 'b');
  const std::vector<ChannelBinding> bindings{binding(1, longest, HopRole::subscriber),
                                             binding(2, too_long, HopRole::subscriber),
                                             binding(3, "FINE", HopRole::subscriber)};
  const Status status = adapter->configure(bindings);
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 1u) << status.error;
  EXPECT_EQ(status.refused[0].channel, 2u);
  EXPECT_EQ(status.refused[0].reason, *transport_name_problem(SegmentType::lcm, too_long));
  EXPECT_NE(status.error.find("at most 63 characters"), std::string::npos) << status.error;
  ASSERT_TRUE(adapter->start(sink_).ok);
  EXPECT_EQ(adapter->send(outbound(1, Bytes{1})), SendStatus::sent);
  EXPECT_EQ(adapter->send(outbound(3, Bytes{1})), SendStatus::sent);
  EXPECT_EQ(adapter->send(outbound(2, Bytes{1})), SendStatus::failed);
  // Without the long name, nothing is refused.
  EXPECT_TRUE(adapter->configure(std::vector<ChannelBinding>{bindings[0], bindings[2]}).ok);
  adapter->stop();
}

// The envelope decoder the adapter runs (cosmic/lcm_wire.hpp) against what lcm-gen encodes.
Bytes encoded(const ::cosmic::envelope& e) {
  Bytes out(static_cast<std::size_t>(e.getEncodedSize()));
  EXPECT_EQ(e.encode(out.data(), 0, static_cast<int>(out.size())), static_cast<int>(out.size()));
  return out;
}

TEST(LcmWire, TheFingerprintIsLcmGens) {
  EXPECT_EQ(::cosmic::envelope::getHash(), static_cast<std::int64_t>(kLcmEnvelopeHash));
  ::cosmic::envelope e{};
  EXPECT_EQ(encoded(e).size(), kLcmEnvelopeHeaderSize);
}

TEST(LcmWire, DecodesWhatLcmGenEncodesWithoutCopying) {
  ::cosmic::envelope e{};
  e.subject = -1;  // subject 0xFFFFFFFFFFFFFFFF
  e.origin = INT64_MIN;
  e.sequence = -1;
  e.hop_count = -1;
  e.created_ns = 1'700'000'000'000'000'000;
  e.age_ns = -5;  // the router's ingress check refuses it; the decoder only reports it
  e.payload = {9, 8, 7};
  e.payload_size = 3;
  const Bytes bytes = encoded(e);
  const auto decoded = decode_lcm_envelope(bytes, 3);
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(decoded->header.subject, 0xFFFFFFFFFFFFFFFFull);
  EXPECT_EQ(decoded->header.origin, 0x8000000000000000ull);
  EXPECT_EQ(decoded->header.sequence, 0xFFFFFFFFu);
  EXPECT_EQ(decoded->header.hop_count, 255u);
  EXPECT_EQ(decoded->header.created_ns, 1'700'000'000'000'000'000);
  EXPECT_EQ(decoded->header.age_ns, -5);
  ASSERT_EQ(decoded->payload.size(), 3u);
  EXPECT_EQ(decoded->payload.data(), bytes.data() + kLcmEnvelopeHeaderSize);
  EXPECT_EQ(Bytes(decoded->payload.begin(), decoded->payload.end()), e.payload);

  ::cosmic::envelope empty{};
  const Bytes no_payload = encoded(empty);
  ASSERT_TRUE(decode_lcm_envelope(no_payload, 0).has_value());
  EXPECT_TRUE(decode_lcm_envelope(no_payload, 0)->payload.empty());
}

TEST(LcmWire, RefusesAnythingButExactlyOneEnvelopeWithinTheLimit) {
  ::cosmic::envelope e{};
  e.payload = Bytes(10, 0x5a);
  e.payload_size = 10;
  const Bytes valid = encoded(e);
  ASSERT_TRUE(decode_lcm_envelope(valid, 10).has_value());
  EXPECT_FALSE(decode_lcm_envelope(valid, 9).has_value());  // above max_message_size
  auto with_payload_size = [&](std::uint32_t v) {
    Bytes b = valid;
    for (int i = 0; i < 4; ++i) b[kLcmEnvelopePayloadSizeOffset + i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
    return b;
  };
  Bytes wrong_hash = valid;
  wrong_hash[7] ^= 1;
  Bytes trailing = valid;
  trailing.push_back(0);
  for (const Bytes& bad : {Bytes{}, Bytes(valid.begin(), valid.begin() + 48), Bytes(valid.begin(), valid.end() - 1), trailing,
                           wrong_hash, with_payload_size(static_cast<std::uint32_t>(-5)), with_payload_size(11),
                           with_payload_size(9), with_payload_size(0x7fffffff), with_payload_size(0xffffffff)}) {
    EXPECT_FALSE(decode_lcm_envelope(bad, UINT64_MAX).has_value()) << bad.size();
  }
}

}  // namespace
}  // namespace cosmic

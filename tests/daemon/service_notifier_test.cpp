// sd_notify messages of cosmicd, received on a NOTIFY_SOCKET of the test's own.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <atomic>
#include <mutex>
#include <thread>
#include <utility>

#include "cosmic/config_loader.hpp"
#include "cosmic/memory_adapter.hpp"
#include "service_notifier.hpp"

namespace {

class QuietLogger final : public cosmic::Logger {
 public:
  void log(cosmic::LogLevel, std::string_view) override {}
};

// A datagram socket standing in for systemd's notification socket. A thread keeps reading it:
// the kernel queues only a few datagrams per socket (net.unix.max_dgram_qlen) and sd_notify
// blocks when they are not taken.
class NotifySocket {
 public:
  NotifySocket() {
    path_ = (std::filesystem::temp_directory_path() / ("cosmic-notify-" + std::to_string(::getpid()))).string();
    ::unlink(path_.c_str());
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strcpy(address.sun_path, path_.c_str());
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
    timeval timeout{0, 20'000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
    reader_ = std::thread([this] {
      char buffer[4096];
      while (running_) {
        const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
        if (n <= 0) continue;
        std::lock_guard lock(mutex_);
        received_.append(buffer, static_cast<std::size_t>(n)).append("\n");
      }
    });
  }
  ~NotifySocket() {
    running_ = false;
    reader_.join();
    ::close(fd_);
    ::unlink(path_.c_str());
    ::unsetenv("NOTIFY_SOCKET");
  }
  // Every message received since the last call, concatenated (sd_notify is synchronous: a
  // message sent before this call has been queued already; give the reader one poll period).
  std::string drain() {
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    std::lock_guard lock(mutex_);
    return std::exchange(received_, {});
  }

 private:
  std::string path_;
  int fd_ = -1;
  std::atomic<bool> running_{true};
  std::mutex mutex_;
  std::string received_;
  std::thread reader_;
};

constexpr const char* kConfig = R"(
gateway: {name: gw}
segments:
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: speed, subject: 1, class: srt, period: 1ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}
)";

class ServiceNotifierTest : public ::testing::Test {
 protected:
  ServiceNotifierTest()
      : gateway(
            [this](const cosmic::SegmentSpec& spec, const cosmic::GatewayIdentity&, cosmic::Logger&) {
              auto adapter = std::make_unique<cosmic::MemoryAdapter>(spec.name);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 7) {
    ::setenv("WATCHDOG_USEC", "20000", 1);  // 20 ms: pings every 10 ms
    ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
    gateway.start(cosmic::parse_config(kConfig, "t.yaml").config);
  }
  ~ServiceNotifierTest() override {
    adapters["viz"]->hold_sends(false);
    gateway.stop();
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
  }

  // Ticks the notifier for `duration`, as the daemon's control loop does.
  std::string tick_for(cosmicd::ServiceNotifier& notifier, std::chrono::milliseconds duration) {
    const auto end = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < end) {
      notifier.tick(gateway);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // loop pacing, not a wait for a condition
    }
    return socket.drain();
  }

  NotifySocket socket;
  QuietLogger log;
  std::map<std::string, cosmic::MemoryAdapter*> adapters;
  cosmic::Gateway gateway;
};

TEST_F(ServiceNotifierTest, ReadyStatusAndWatchdogArrive) {
  cosmicd::ServiceNotifier notifier;
  const std::string messages = tick_for(notifier, std::chrono::milliseconds(100));
  EXPECT_NE(messages.find("READY=1"), std::string::npos);
  EXPECT_NE(messages.find("STATUS=2/2 segments up, 1 channels bound"), std::string::npos) << messages;
  EXPECT_NE(messages.find("WATCHDOG=1"), std::string::npos);
}

TEST_F(ServiceNotifierTest, ReadyWaitsForSegmentsUntilTheGracePeriod) {
  adapters["viz"]->set_health(cosmic::SegmentHealth::down, "cable");
  cosmicd::ServiceNotifier notifier(std::chrono::milliseconds(200));
  EXPECT_EQ(tick_for(notifier, std::chrono::milliseconds(50)).find("READY=1"), std::string::npos);
  const std::string later = tick_for(notifier, std::chrono::milliseconds(250));
  EXPECT_NE(later.find("READY=1"), std::string::npos);
  EXPECT_NE(later.find("viz down"), std::string::npos) << later;
}

TEST_F(ServiceNotifierTest, StalledRouterStopsWatchdogPings) {
  cosmicd::ServiceNotifier notifier;
  tick_for(notifier, std::chrono::milliseconds(50));
  adapters["viz"]->hold_sends(true);  // the router thread blocks inside send()
  for (int i = 0; i < 5; ++i) adapters["lan"]->inject("speed", {1});
  tick_for(notifier, std::chrono::milliseconds(50));  // let the notifier see the stall once
  EXPECT_EQ(tick_for(notifier, std::chrono::milliseconds(150)).find("WATCHDOG=1"), std::string::npos);
  adapters["viz"]->hold_sends(false);
  EXPECT_NE(tick_for(notifier, std::chrono::milliseconds(150)).find("WATCHDOG=1"), std::string::npos);
}

}  // namespace

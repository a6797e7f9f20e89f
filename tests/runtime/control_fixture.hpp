// Helpers shared by the control protocol tests (control_test.cpp, control_limits_test.cpp): a
// logger that keeps its lines, the gateway configuration the tests start from, a client on the
// Unix socket and the ControlTest fixture (a gateway on in-memory segments, a control server on a
// socket of its own and a gate to hold admission work).
#pragma once

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "cosmic/control_server.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic::control_test {

using Json = nlohmann::json;

class QuietLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override {
    std::lock_guard lock(mutex);
    lines.emplace_back(message);
  }
  std::mutex mutex;
  std::vector<std::string> lines;
};

inline constexpr const char* kConfig = R"(
gateway: {name: gw}
segments:
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}
)";

// A connected client socket.
class Client {
 public:
  explicit Client(const std::string& path) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::strcpy(address.sun_path, path.c_str());
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
    timeval timeout{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  ~Client() { ::close(fd_); }
  bool connected() const { return connected_; }
  int fd() const { return fd_; }
  void send_raw(const std::string& data) {
    ASSERT_EQ(::send(fd_, data.data(), data.size(), MSG_NOSIGNAL), static_cast<ssize_t>(data.size()));
  }
  // For a peer that may close at any moment: false once the server has gone.
  bool try_send(const std::string& data) {
    return ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(data.size());
  }
  std::string read_line() {
    std::string line;
    char c;
    while (::read(fd_, &c, 1) == 1) {
      if (c == '\n') return line;
      line += c;
    }
    return line;
  }
  Json call(const Json& request) {
    send_raw(request.dump() + "\n");
    return Json::parse(read_line(), nullptr, false);
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
};

class ControlTest : public ::testing::Test {
 protected:
  explicit ControlTest(const char* config = kConfig)
      : dir(std::filesystem::temp_directory_path() / ("cosmic-control-" + std::to_string(::getpid()))),
        gateway(
            [this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) {
              auto adapter = std::make_unique<MemoryAdapter>(spec.name);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 0x42) {
    std::filesystem::remove_all(dir);
    socket_path = (dir / "run" / "control.sock").string();
    gateway.start(parse_config(config, "test.yaml").config);
  }
  ~ControlTest() override {
    open_gate();
    if (admission_thread.joinable()) admission_thread.join();
    running = false;
    if (server_thread.joinable()) server_thread.join();
    server.reset();
    gateway.stop();
    std::filesystem::remove_all(dir);
  }

  enum class Admission { inline_run, server_worker, gated };
  struct Setup {
    AccessPolicy policy;
    std::function<void(ControlServerOptions&)> tune = [](ControlServerOptions&) {};
    Admission admission = Admission::inline_run;
    ChangeObserver on_change;
  };

  void serve(AccessPolicy policy = {}, std::size_t max_clients = 32) {
    Setup setup;
    setup.policy = std::move(policy);
    setup.tune = [max_clients](ControlServerOptions& o) { o.max_clients = max_clients; };
    serve_with(setup);
  }

  void serve_with(const Setup& setup) {
    ControlServerOptions options;
    options.path = socket_path;
    options.max_request_bytes = 4096;
    options.max_pending_output = 8192;
    options.privileged = [](const PeerCredentials&) { return true; };
    setup.tune(options);
    server = std::make_unique<ControlServer>(
        options, [this](std::string_view line, const PeerCredentials& peer, ControlServer::Responder later) {
          return protocol->handle(line, peer, std::move(later));
        });
    Offload offload;
    if (setup.admission == Admission::server_worker) offload = server->offload();
    if (setup.admission == Admission::gated) offload = gated_offload();
    protocol = std::make_unique<ControlProtocol>(
        gateway, [] { return parse_config("nonsense: [", "reload.yaml"); }, setup.policy, log, setup.on_change,
        offload);
    const Status opened = server->open();
    ASSERT_TRUE(opened.ok) << opened.error;
    server_thread = std::thread([this] {
      while (running) server->run_for(std::chrono::milliseconds(20));
    });
  }

  // Admission work waits for open_gate(): an admission as long as the test wants.
  Offload gated_offload() {
    return [this](std::function<void()> work, std::function<void()> done) {
      if (admission_thread.joinable()) admission_thread.join();  // the previous one has posted its answer
      admission_thread = std::thread([this, work, done] {
        {
          std::unique_lock lock(gate_mutex);
          gate_changed.wait(lock, [this] { return gate_open; });
        }
        work();
        server->post(done);
      });
    };
  }
  void open_gate() {
    std::lock_guard lock(gate_mutex);
    gate_open = true;
    gate_changed.notify_all();
  }

  std::filesystem::path dir;
  std::string socket_path;
  QuietLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway;
  std::unique_ptr<ControlProtocol> protocol;
  std::unique_ptr<ControlServer> server;
  std::atomic<bool> running{true};
  std::thread server_thread;
  std::mutex gate_mutex;
  std::condition_variable gate_changed;
  bool gate_open = false;
  std::thread admission_thread;
};

}  // namespace cosmic::control_test

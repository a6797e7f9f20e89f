// The control protocol over a real Unix socket, against a gateway on in-memory segments.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <thread>

#include "cosmic/control_server.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

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

constexpr const char* kConfig = R"(
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
  void send_raw(const std::string& data) { ASSERT_EQ(::send(fd_, data.data(), data.size(), MSG_NOSIGNAL), static_cast<ssize_t>(data.size())); }
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
  ControlTest()
      : dir(std::filesystem::temp_directory_path() / ("cosmic-control-" + std::to_string(::getpid()))),
        gateway([](const SegmentSpec& spec, const GatewayIdentity&, Logger&) { return std::make_unique<MemoryAdapter>(spec.name); },
                log, 0x42) {
    std::filesystem::remove_all(dir);
    socket_path = (dir / "run" / "control.sock").string();
    gateway.start(parse_config(kConfig, "test.yaml").config);
  }
  ~ControlTest() override {
    running = false;
    if (server_thread.joinable()) server_thread.join();
    server.reset();
    gateway.stop();
    std::filesystem::remove_all(dir);
  }

  void serve(AccessPolicy policy = {}, std::size_t max_clients = 32) {
    protocol = std::make_unique<ControlProtocol>(gateway, [] { return parse_config("nonsense: [", "reload.yaml"); }, policy, log);
    ControlServerOptions options;
    options.path = socket_path;
    options.max_request_bytes = 4096;
    options.max_clients = max_clients;
    options.max_pending_output = 8192;
    server = std::make_unique<ControlServer>(
        options, [this](std::string_view line, const PeerCredentials& peer, ControlServer::Responder later) {
          return protocol->handle(line, peer, std::move(later));
        });
    const Status opened = server->open();
    ASSERT_TRUE(opened.ok) << opened.error;
    server_thread = std::thread([this] {
      while (running) server->run_for(std::chrono::milliseconds(20));
    });
  }

  std::filesystem::path dir;
  std::string socket_path;
  QuietLogger log;
  Gateway gateway;
  std::unique_ptr<ControlProtocol> protocol;
  std::unique_ptr<ControlServer> server;
  std::atomic<bool> running{true};
  std::thread server_thread;
};

TEST_F(ControlTest, SocketAndDirectoryPermissions) {
  serve();
  struct stat socket_stat {};
  ASSERT_EQ(::stat(socket_path.c_str(), &socket_stat), 0);
  EXPECT_EQ(socket_stat.st_mode & 0777, 0660u);
  struct stat dir_stat {};
  ASSERT_EQ(::stat((dir / "run").c_str(), &dir_stat), 0);
  EXPECT_EQ(dir_stat.st_mode & 0777, 0750u);
}

TEST_F(ControlTest, StatusSegmentsAndChannels) {
  serve();
  Client client(socket_path);
  ASSERT_TRUE(client.connected());
  const Json status = client.call({{"command", "status"}});
  EXPECT_EQ(status["ok"], true);
  EXPECT_EQ(status["gateway"]["name"], "gw");
  EXPECT_EQ(status["channels"]["bound"], 1);
  const Json segments = client.call({{"command", "segments"}});
  ASSERT_EQ(segments["segments"].size(), 2u);
  EXPECT_EQ(segments["segments"][0]["health"], "up");
  const Json channels = client.call({{"command", "channels"}});
  ASSERT_EQ(channels["channels"].size(), 1u);
  const Json& speed = channels["channels"][0];
  EXPECT_EQ(speed["verdict"], "bound");
  ASSERT_EQ(speed["segments"].size(), 2u);
  for (const char* key : {"rx", "tx", "dropped"}) EXPECT_TRUE(speed["segments"][0].contains(key)) << key;
  for (const char* reason : {"expired", "rate", "queue_full", "duplicate", "decode_error", "no_route"}) {
    EXPECT_TRUE(speed["segments"][0]["dropped"].contains(reason)) << reason;
  }
  const Json one = client.call({{"command", "channel"}, {"name", "speed"}});
  EXPECT_EQ(one["channel"]["admission"]["verdict"], "bound");
  EXPECT_EQ(client.call({{"command", "channel"}, {"name", "nope"}})["error"]["code"], "not_found");
}

TEST_F(ControlTest, BadRequestsGetClearErrorsAndTheConnectionSurvives) {
  serve();
  Client client(socket_path);
  client.send_raw("this is not json\n");
  EXPECT_EQ(Json::parse(client.read_line())["error"]["code"], "bad_request");
  EXPECT_EQ(client.call({{"nothing", 1}})["error"]["code"], "bad_request");
  EXPECT_EQ(client.call({{"command", "fly"}})["error"]["code"], "unknown_command");
  EXPECT_EQ(client.call({{"command", "unbind"}})["error"]["code"], "bad_request");
  EXPECT_EQ(client.call({{"command", "bind"}, {"yaml", "{name: x"}})["error"]["code"], "config_error");
  EXPECT_EQ(client.call({{"command", "status"}})["ok"], true);
}

TEST_F(ControlTest, RejectedBindAnswersWithReasonAndChangesNothing) {
  serve();
  Client client(socket_path);
  const Json answer = client.call(
      {{"command", "bind"},
       {"yaml", "{name: brake, subject: 9, class: hrt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [viz]}"}});
  EXPECT_EQ(answer["ok"], false);
  EXPECT_EQ(answer["error"]["code"], "rejected");
  EXPECT_EQ(answer["channels"][0]["verdict"], "rejected");
  EXPECT_EQ(client.call({{"command", "channels"}})["channels"].size(), 1u);
}

TEST_F(ControlTest, ReloadOfABrokenFileKeepsTheRunningConfiguration) {
  serve();
  Client client(socket_path);
  const Json answer = client.call({{"command", "reload"}});
  EXPECT_EQ(answer["error"]["code"], "config_error");
  EXPECT_FALSE(answer["errors"].empty());
  EXPECT_EQ(client.call({{"command", "channels"}})["channels"].size(), 1u);
}

TEST_F(ControlTest, PermissionsAreCheckedPerCommandClass) {
  AccessPolicy policy;
  policy.may_modify = [](const PeerCredentials&) { return false; };
  serve(policy);
  Client client(socket_path);
  EXPECT_EQ(client.call({{"command", "status"}})["ok"], true);
  EXPECT_EQ(client.call({{"command", "unbind"}, {"name", "speed"}})["error"]["code"], "permission_denied");
  EXPECT_NE(gateway.knowledge_base().find_bound("speed"), nullptr);
}

TEST_F(ControlTest, OversizedRequestIsRefusedAndClosed) {
  serve();
  Client client(socket_path);
  client.send_raw(std::string(10'000, 'x'));
  EXPECT_EQ(Json::parse(client.read_line(), nullptr, false)["error"]["code"], "too_large");
  Client other(socket_path);
  EXPECT_EQ(other.call({{"command", "status"}})["ok"], true);
}

TEST_F(ControlTest, PipelinedRequestsAreAllAnsweredWhileOutputStaysBounded) {
  serve();
  Client greedy(socket_path);
  std::string burst;
  constexpr int kRequests = 3000;  // about 2 MB of answers against an 8 KiB output allowance
  for (int i = 0; i < kRequests; ++i) burst += R"({"command":"channels"})" "\n";
  std::thread sender([&] { greedy.send_raw(burst); });
  Client other(socket_path);  // the server keeps serving others while the greedy one is paused
  EXPECT_EQ(other.call({{"command", "status"}})["ok"], true);
  int answers = 0;
  while (answers < kRequests && Json::parse(greedy.read_line(), nullptr, false).value("ok", false)) ++answers;
  sender.join();
  EXPECT_EQ(answers, kRequests);
}

TEST_F(ControlTest, ManyClientsAtOnceAndALimit) {
  serve({}, 4);
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < 4; ++i) clients.push_back(std::make_unique<Client>(socket_path));
  for (auto& c : clients) EXPECT_EQ(c->call({{"command", "status"}})["ok"], true);
  Client extra(socket_path);
  EXPECT_EQ(Json::parse(extra.read_line(), nullptr, false)["error"]["code"], "busy");
}

}  // namespace
}  // namespace cosmic

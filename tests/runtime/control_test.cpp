// The control protocol over a real Unix socket, against a gateway on in-memory segments.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <poll.h>
#include <sys/resource.h>

#include <atomic>
#include <condition_variable>
#include <cstring>
#include <fstream>
#include <map>
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
  int fd() const { return fd_; }
  void send_raw(const std::string& data) { ASSERT_EQ(::send(fd_, data.data(), data.size(), MSG_NOSIGNAL), static_cast<ssize_t>(data.size())); }
  // For a peer that may close at any moment: false once the server has gone.
  bool try_send(const std::string& data) { return ::send(fd_, data.data(), data.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(data.size()); }
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
        gateway([this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) {
                  auto adapter = std::make_unique<MemoryAdapter>(spec.name);
                  adapters[spec.name] = adapter.get();
                  return adapter;
                },
                log, 0x42) {
    std::filesystem::remove_all(dir);
    socket_path = (dir / "run" / "control.sock").string();
    gateway.start(parse_config(kConfig, "test.yaml").config);
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
    protocol = std::make_unique<ControlProtocol>(gateway, [] { return parse_config("nonsense: [", "reload.yaml"); },
                                                 setup.policy, log, setup.on_change, offload);
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

// A channel of the configuration that admission rejected is not "not found": the answer says
// rejected and why (what libcosmic-client's cosmic_check_channel shows a component).
TEST_F(ControlTest, AChannelRejectedAtLoadIsAnsweredRejectedWithTheReasons) {
  const std::string config = std::string(kConfig) +
      "  - {name: hard, subject: 2, class: hrt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}\n";
  const BindResult reloaded = gateway.reload(parse_config(config, "test.yaml").config);
  ASSERT_TRUE(reloaded.applied) << reloaded.error;
  serve();
  Client client(socket_path);
  const Json answer = client.call({{"command", "channel"}, {"name", "hard"}});
  EXPECT_EQ(answer["ok"], false);
  ASSERT_EQ(answer["error"]["code"], "rejected") << answer.dump();
  ASSERT_FALSE(answer["error"]["reasons"].empty());
  EXPECT_NE(answer["error"]["reasons"][0].get<std::string>().find("declares no real-time guarantee"), std::string::npos);
  EXPECT_EQ(answer["error"]["admission"]["verdict"], "rejected");
  EXPECT_EQ(client.call({{"command", "channel"}, {"name", "nope"}})["error"]["code"], "not_found");
  EXPECT_EQ(client.call({{"command", "channel"}, {"name", "speed"}})["ok"], true);
}

// An in-memory segment whose transport negotiates QoS (as DDS does) and has a rate-limited
// binding protocol (as CAN has): what it counts is what the control answers show.
class NegotiatingAdapter final : public SegmentAdapter {
 public:
  NegotiatingAdapter(const std::string& name, const std::atomic<std::uint64_t>& incompatible)
      : inner_(name), incompatible_(incompatible) {}
  Status start(EventSink& sink) override { return inner_.start(sink); }
  Status configure(std::span<const ChannelBinding> bindings) override { return inner_.configure(bindings); }
  SendStatus send(const OutboundEvent& event) override { return inner_.send(event); }
  HealthReport health() const override { return inner_.health(); }
  AdapterStatistics statistics() const override {
    AdapterStatistics s = inner_.statistics();
    s.binding_requests_over_limit = incompatible_.load() * 10;
    return s;
  }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return 0; }
  std::optional<std::uint64_t> incompatible_peers(ChannelId) const override { return incompatible_.load(); }
  void stop() override { inner_.stop(); }

 private:
  MemoryAdapter inner_;
  const std::atomic<std::uint64_t>& incompatible_;
};

// Remote endpoints refused for their QoS are a per-hop count and a per-channel mismatch line;
// a transport without negotiation (LCM, CAN) answers null.
TEST(ControlAnswers, IncompatiblePeersAndBindingRequestsOverTheLimit) {
  QuietLogger log;
  std::atomic<std::uint64_t> incompatible{0};
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        if (spec.name == "lan") return std::make_unique<NegotiatingAdapter>(spec.name, incompatible);
        return std::make_unique<MemoryAdapter>(spec.name);
      },
      log, 0x42);
  ASSERT_TRUE(gateway.start(parse_config(kConfig, "test.yaml").config).applied);
  ControlProtocol protocol(gateway, [] { return parse_config("nonsense: [", "reload.yaml"); }, AccessPolicy{}, log);
  auto call = [&](const Json& request) { return Json::parse(protocol.handle(request.dump(), PeerCredentials{})); };
  auto hop = [](const Json& channel, const std::string& segment) {
    for (const auto& s : channel["segments"]) {
      if (s["segment"] == segment) return s;
    }
    return Json();
  };

  Json speed = call({{"command", "channels"}})["channels"][0];
  EXPECT_EQ(hop(speed, "lan")["incompatible"], 0);
  EXPECT_TRUE(hop(speed, "viz")["incompatible"].is_null());
  EXPECT_EQ(speed["mismatches"], Json::array());

  incompatible = 2;  // two remote writers of `speed` refused on lan (the gateway reads there)
  for (const Json& answer : {call({{"command", "channels"}})["channels"][0], call({{"command", "channel"}, {"name", "speed"}})["channel"]}) {
    EXPECT_EQ(hop(answer, "lan")["incompatible"], 2) << answer;
    EXPECT_EQ(hop(answer, "lan")["matched"], 0) << answer;
    ASSERT_EQ(answer["mismatches"].size(), 1u) << answer;
    EXPECT_EQ(answer["mismatches"][0],
              "2 remote writers on lan refused for incompatible QoS (not matched; the log names the policy)");
  }

  const Json segments = call({{"command", "segments"}})["segments"];
  for (const auto& s : segments) {
    const Json& over = s["adapter"]["binding_requests_over_limit"];
    if (s["name"] == "lan") {
      EXPECT_EQ(over, 20);
    } else {
      EXPECT_TRUE(over.is_null()) << s;  // no binding protocol
    }
  }
  gateway.stop();
}

// Issue 9, item 10: what a segment's transport refuses is `failed` with its reason in every
// answer that shows the channel, never `bound`.
TEST_F(ControlTest, AChannelASegmentRefusesIsFailedWithItsReason) {
  serve();
  Client client(socket_path);
  ASSERT_TRUE(client.connected());
  adapters.at("viz")->refuse_channel("speed", "LCM channel names have at most 63 characters");
  // Any change reconfigures every segment: this bind's own channel is carried, speed is not.
  const Json bound = client.call({{"command", "bind"},
                                  {"yaml", "{name: plot, subject: 7, class: nrt, omission_degree: 1, publishers: [lan], subscribers: [viz]}"}});
  EXPECT_EQ(bound["ok"], true) << bound.dump();
  const Json channels = client.call({{"command", "channels"}});
  ASSERT_EQ(channels["channels"].size(), 2u);
  for (const auto& c : channels["channels"]) {
    EXPECT_EQ(c["verdict"], c["name"] == "speed" ? "failed" : "bound") << c.dump();
  }
  const Json one = client.call({{"command", "channel"}, {"name", "speed"}});
  ASSERT_EQ(one["ok"], true);
  EXPECT_EQ(one["channel"]["verdict"], "failed");
  EXPECT_EQ(one["channel"]["admission"]["verdict"], "failed");
  bool has_reason = false;
  for (const auto& reason : one["channel"]["reasons"]) {
    has_reason |= reason.get<std::string>() == "segment viz does not carry it: LCM channel names have at most 63 characters";
  }
  EXPECT_TRUE(has_reason) << one.dump();
  const Json status = client.call({{"command", "status"}});
  EXPECT_EQ(status["channels"]["bound"], 1);
  EXPECT_EQ(status["channels"]["failed"], 1);
  // A bind whose own channel is refused is refused as a whole, with the transport's reason.
  adapters.at("lan")->refuse_channel("more", "cannot create topic cosmic/more");
  const Json refused = client.call({{"command", "bind"},
                                    {"yaml", "{name: more, subject: 8, class: nrt, publishers: [lan], subscribers: [viz]}"}});
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["error"]["code"], "bind_failed");
  EXPECT_NE(refused["error"]["message"].get<std::string>().find("segment lan does not carry channel more: cannot create topic cosmic/more"),
            std::string::npos)
      << refused.dump();
  ASSERT_EQ(refused["channels"].size(), 1u);
  EXPECT_EQ(refused["channels"][0]["verdict"], "failed");
  EXPECT_EQ(client.call({{"command", "channel"}, {"name", "more"}})["error"]["code"], "not_found");
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

// `count` LCM-to-DDS channels in one bind file: an admission with real work in it.
std::string many_channels(int count, int first_subject) {
  std::string yaml = "channels:\n";
  for (int i = 0; i < count; ++i) {
    yaml += "  - {name: bulk" + std::to_string(first_subject + i) + ", subject: " + std::to_string(first_subject + i) +
            ", class: nrt, publishers: [viz], subscribers: [lan]}\n";
  }
  return yaml;
}

TEST_F(ControlTest, StatusIsAnsweredWhileALongAdmissionRunsAndASecondBindIsBusy) {
  Setup setup;
  setup.admission = Admission::gated;
  serve_with(setup);
  Client binder(socket_path);
  binder.send_raw(Json{{"command", "bind"}, {"yaml", many_channels(40, 1000)}}.dump() + "\n");
  Client other(socket_path);
  // The control thread answers while the admission waits on the gate.
  EXPECT_EQ(other.call({{"command", "status"}})["ok"], true);
  const Json second = other.call({{"command", "bind"}, {"yaml", many_channels(1, 5000)}});
  EXPECT_EQ(second["error"]["code"], "busy");
  EXPECT_NE(second["error"]["message"].get<std::string>().find("bind of bulk1000"), std::string::npos);
  EXPECT_EQ(other.call({{"command", "unbind"}, {"name", "speed"}})["error"]["code"], "busy");
  EXPECT_EQ(other.call({{"command", "reload"}})["error"]["code"], "busy");
  open_gate();
  const Json first = Json::parse(binder.read_line(), nullptr, false);
  EXPECT_EQ(first["ok"], true) << first.dump();
  EXPECT_EQ(first["channels"].size(), 40u);
  EXPECT_EQ(other.call({{"command", "channels"}})["channels"].size(), 41u);
  // Once it is done, binding works again.
  EXPECT_EQ(other.call({{"command", "bind"}, {"yaml", many_channels(1, 5000)}})["ok"], true);
}

TEST_F(ControlTest, AdmissionOnTheServersWorkerAnswersInOrder) {
  Setup setup;
  setup.admission = Admission::server_worker;
  setup.tune = [](ControlServerOptions& o) { o.max_request_bytes = 64 * 1024; };
  serve_with(setup);
  Client client(socket_path);
  // Pipelined: the status after the bind waits for the bind's deferred answer.
  client.send_raw(Json{{"command", "bind"}, {"yaml", many_channels(200, 1000)}}.dump() + "\n" + R"({"command":"status"})" + "\n");
  const Json bound = Json::parse(client.read_line(), nullptr, false);
  EXPECT_EQ(bound["ok"], true) << bound.dump();
  EXPECT_EQ(bound["channels"].size(), 200u);  // the bind's answer comes first
  EXPECT_TRUE(Json::parse(client.read_line(), nullptr, false).contains("gateway"));
  EXPECT_EQ(client.call({{"command", "channels"}})["channels"].size(), 201u);
  EXPECT_EQ(client.call({{"command", "reload"}})["error"]["code"], "config_error");  // its load ran on the worker too
}

TEST_F(ControlTest, PlanCommittedAfterTheBindingsChangedIsRefused) {
  BindPlan plan = gateway.bind_plan_input(parse_channels(many_channels(1, 7000), "t", gateway.config()).channels);
  Gateway::plan_bind(plan);
  ASSERT_TRUE(gateway.unbind("speed"));
  const BindResult result = gateway.commit_bind(std::move(plan));
  EXPECT_FALSE(result.applied);
  EXPECT_EQ(gateway.knowledge_base().find_bound("bulk7000"), nullptr);
}

// Connects and checks that the server took the connection (a status round trip).
std::unique_ptr<Client> admitted(const std::string& path) {
  auto client = std::make_unique<Client>(path);
  EXPECT_EQ(client->call({{"command", "status"}})["ok"], true);
  return client;
}

std::string refusal(const std::string& path) {
  Client refused(path);
  const Json answer = Json::parse(refused.read_line(), nullptr, false);
  EXPECT_EQ(answer["error"]["code"], "busy") << answer.dump();
  return answer.value("error", Json::object()).value("message", "");
}

TEST_F(ControlTest, AdminsKeepReservedSlots) {
  std::atomic<bool> admin{false};
  Setup setup;
  setup.tune = [&admin](ControlServerOptions& o) {
    o.max_clients = 4;
    o.privileged_reserve = 2;
    o.privileged = [&admin](const PeerCredentials&) { return admin.load(); };
  };
  serve_with(setup);
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < 2; ++i) clients.push_back(admitted(socket_path));
  EXPECT_NE(refusal(socket_path).find("reserved for administrators"), std::string::npos);
  admin = true;
  for (int i = 0; i < 2; ++i) clients.push_back(admitted(socket_path));
  EXPECT_NE(refusal(socket_path).find("too many control clients"), std::string::npos);
}

TEST_F(ControlTest, OneUnprivilegedUidGetsAShare) {
  std::atomic<bool> admin{false};
  Setup setup;
  setup.tune = [&admin](ControlServerOptions& o) {
    o.max_clients = 10;
    o.privileged_reserve = 0;
    o.max_clients_per_uid = 2;
    o.privileged = [&admin](const PeerCredentials&) { return admin.load(); };
  };
  serve_with(setup);
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < 2; ++i) clients.push_back(admitted(socket_path));
  EXPECT_NE(refusal(socket_path).find("limit per user"), std::string::npos);
  admin = true;  // privileged peers are not limited per uid
  clients.push_back(admitted(socket_path));
}

TEST_F(ControlTest, IncompleteRequestTimesOutEvenWhenBytesKeepTrickling) {
  Setup setup;
  setup.tune = [](ControlServerOptions& o) {
    o.request_timeout = std::chrono::milliseconds(300);
    o.idle_timeout = std::chrono::seconds(60);
  };
  serve_with(setup);
  Client client(socket_path);
  client.send_raw(R"({"command":)");
  // One more byte whenever 20 ms pass without an answer: an idle timer would never fire. The server
  // may answer and close between the poll and the send; the answer stays queued for read_line.
  pollfd ready{client.fd(), POLLIN, 0};
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (::poll(&ready, 1, 20) == 0 && std::chrono::steady_clock::now() < give_up && client.try_send(" ")) {
  }
  const Json answer = Json::parse(client.read_line(), nullptr, false);
  EXPECT_EQ(answer["error"]["code"], "timeout") << answer.dump();
}

TEST_F(ControlTest, ARegularFileAtTheSocketPathIsRefusedAndKept) {
  std::filesystem::create_directories(dir / "run");
  std::ofstream(socket_path) << "precious\n";
  ControlServerOptions options;
  options.path = socket_path;
  ControlServer server_at_file(options, [](std::string_view, const PeerCredentials&, ControlServer::Responder) {
    return std::optional<std::string>("{}\n");
  });
  const Status opened = server_at_file.open();
  EXPECT_FALSE(opened.ok);
  EXPECT_NE(opened.error.find("not a socket"), std::string::npos) << opened.error;
  server_at_file.close_all();
  std::ifstream kept(socket_path);
  std::string content;
  std::getline(kept, content);
  EXPECT_EQ(content, "precious");
}

TEST_F(ControlTest, AcceptAtTheDescriptorLimitRefusesInsteadOfSpinning) {
#ifdef __SANITIZE_ADDRESS__
  // UBSan's vptr check needs a free descriptor of its own and reports a false error without one.
  GTEST_SKIP() << "runs in the non-sanitizer build only (the sanitizer runtime needs descriptors)";
#endif
  serve();
  const int client = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(client, 0);
  rlimit saved{};
  ::getrlimit(RLIMIT_NOFILE, &saved);
  const int probe = ::dup(0);
  rlimit low = saved;
  low.rlim_cur = static_cast<rlim_t>(probe + 8);
  ::close(probe);
  ASSERT_EQ(::setrlimit(RLIMIT_NOFILE, &low), 0);
  std::vector<int> filler;
  for (int fd; (fd = ::dup(0)) >= 0;) filler.push_back(fd);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strcpy(address.sun_path, socket_path.c_str());
  const bool connected = ::connect(client, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  pollfd ready{client, POLLIN, 0};
  const bool answered = connected && ::poll(&ready, 1, 5000) == 1;
  char buffer[512] = {};
  const ssize_t n = answered ? ::read(client, buffer, sizeof buffer - 1) : -1;
  for (const int fd : filler) ::close(fd);
  ::setrlimit(RLIMIT_NOFILE, &saved);
  ::close(client);
  ASSERT_TRUE(connected);
  ASSERT_TRUE(answered) << "the pending connection was never taken off the backlog";
  ASSERT_GT(n, 0);
  const Json answer = Json::parse(std::string(buffer, static_cast<std::size_t>(n)), nullptr, false);
  EXPECT_EQ(answer["error"]["code"], "busy");
  EXPECT_NE(answer["error"]["message"].get<std::string>().find("file descriptors"), std::string::npos);
  // Serving goes on once descriptors are back (a connection racing the refusal above may still
  // be refused: retry until one is served).
  bool served = false;
  for (const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
       !served && std::chrono::steady_clock::now() < give_up;) {
    Client later(socket_path);
    served = later.call({{"command", "status"}}).value("ok", false);
  }
  EXPECT_TRUE(served);
}

TEST_F(ControlTest, DeepNestingIsRefusedBeforeParsingAndLogLinesStayBounded) {
  AccessPolicy policy;
  policy.may_modify = [](const PeerCredentials&) { return false; };
  serve(policy);
  Client client(socket_path);
  const Json deep = client.call(Json::parse(R"({"command":"status","x":)" + std::string(20, '[') + std::string(20, ']') + "}"));
  EXPECT_EQ(deep["error"]["code"], "bad_request");
  client.send_raw(std::string(3000, '[') + "\n");
  EXPECT_EQ(Json::parse(client.read_line(), nullptr, false)["error"]["code"], "bad_request");
  const std::string long_command(3000, 'u');
  client.call({{"command", "unbind"}, {"name", Json::array({Json::array({Json::array({1})})})}});
  client.call({{"command", long_command}});
  std::lock_guard lock(log.mutex);
  for (const auto& line : log.lines) EXPECT_LT(line.size(), 300u) << line.substr(0, 80);
}

TEST_F(ControlTest, DeniedRequestsAreLoggedWithThePidAndNeverAlike) {
  AccessPolicy policy;
  policy.may_modify = [](const PeerCredentials&) { return false; };
  serve(policy);
  Client client(socket_path);
  for (int i = 0; i < 2; ++i) client.call({{"command", "unbind"}, {"name", "speed"}});
  std::vector<std::string> denied;
  {
    std::lock_guard lock(log.mutex);
    for (const auto& line : log.lines) {
      if (line.find("denied") != std::string::npos) denied.push_back(line);
    }
  }
  ASSERT_EQ(denied.size(), 2u);
  EXPECT_NE(denied[0], denied[1]);  // a logger folding repeated lines cannot hide the second
  for (const auto& line : denied) EXPECT_NE(line.find("pid " + std::to_string(::getpid())), std::string::npos) << line;
}

TEST_F(ControlTest, AChangeThatCannotBeSavedIsNotOk) {
  Setup setup;
  setup.on_change = [](const std::string&, const Json&) { return std::string("No space left on device"); };
  serve_with(setup);
  Client client(socket_path);
  const Json answer = client.call({{"command", "unbind"}, {"name", "speed"}});
  EXPECT_EQ(answer["ok"], false);
  EXPECT_EQ(answer["error"]["code"], "not_persisted");
  EXPECT_NE(answer["error"]["message"].get<std::string>().find("No space left"), std::string::npos);
}

}  // namespace
}  // namespace cosmic

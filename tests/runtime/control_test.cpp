// The control protocol over a real Unix socket, against a gateway on in-memory segments.
// This file: socket permissions, the status, segment and channel answers (rejected and refused
// channels, incompatible peers), bad and rejected requests, reload and per-command permissions.
// Request and client limits, concurrent admission, timeouts and hostile input are in
// control_limits_test.cpp; the shared fixture in control_fixture.hpp.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "control_fixture.hpp"
#include "cosmic/control_server.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic::control_test {
namespace {

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
                             "  - {name: hard, subject: 2, class: hrt, period: 10ms, reaction_time: 20ms, "
                             "omission_degree: 1, publishers: [lan], subscribers: [viz]}\n";
  const BindResult reloaded = gateway.reload(parse_config(config, "test.yaml").config);
  ASSERT_TRUE(reloaded.applied) << reloaded.error;
  serve();
  Client client(socket_path);
  const Json answer = client.call({{"command", "channel"}, {"name", "hard"}});
  EXPECT_EQ(answer["ok"], false);
  ASSERT_EQ(answer["error"]["code"], "rejected") << answer.dump();
  ASSERT_FALSE(answer["error"]["reasons"].empty());
  EXPECT_NE(answer["error"]["reasons"][0].get<std::string>().find("declares no real-time guarantee"),
            std::string::npos);
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
    s.transport.push_back(TransportCounter{"binding_requests_over_limit", incompatible_.load() * 10});
    s.transport.push_back(TransportCounter{"own_datagrams_dropped", incompatible_.load() * 100});
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
  ControlProtocol protocol(
      gateway, [] { return parse_config("nonsense: [", "reload.yaml"); }, AccessPolicy{}, log);
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
  for (const Json& answer :
       {call({{"command", "channels"}})["channels"][0], call({{"command", "channel"}, {"name", "speed"}})["channel"]}) {
    EXPECT_EQ(hop(answer, "lan")["incompatible"], 2) << answer;
    EXPECT_EQ(hop(answer, "lan")["matched"], 0) << answer;
    ASSERT_EQ(answer["mismatches"].size(), 1u) << answer;
    EXPECT_EQ(answer["mismatches"][0],
              "2 remote writers on lan refused for incompatible QoS (not matched; the log names the policy)");
  }

  const Json segments = call({{"command", "segments"}})["segments"];
  for (const auto& s : segments) {
    // A transport's own counters appear where it has them, under their names.
    if (s["name"] == "lan") {
      EXPECT_EQ(s["adapter"]["binding_requests_over_limit"], 20);
      EXPECT_EQ(s["adapter"]["own_datagrams_dropped"], 200);
    } else {
      EXPECT_FALSE(s["adapter"].contains("binding_requests_over_limit")) << s;  // no binding protocol
      EXPECT_FALSE(s["adapter"].contains("own_datagrams_dropped")) << s;        // no filter that drops
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
  const Json bound = client.call(
      {{"command", "bind"},
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
    has_reason |=
        reason.get<std::string>() == "segment viz does not carry it: LCM channel names have at most 63 characters";
  }
  EXPECT_TRUE(has_reason) << one.dump();
  const Json status = client.call({{"command", "status"}});
  EXPECT_EQ(status["channels"]["bound"], 1);
  EXPECT_EQ(status["channels"]["failed"], 1);
  // A bind whose own channel is refused is refused as a whole, with the transport's reason.
  adapters.at("lan")->refuse_channel("more", "cannot create topic cosmic/more");
  const Json refused = client.call(
      {{"command", "bind"}, {"yaml", "{name: more, subject: 8, class: nrt, publishers: [lan], subscribers: [viz]}"}});
  EXPECT_EQ(refused["ok"], false);
  EXPECT_EQ(refused["error"]["code"], "bind_failed");
  EXPECT_NE(refused["error"]["message"].get<std::string>().find(
                "segment lan does not carry channel more: cannot create topic cosmic/more"),
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
  const Json answer = client.call({{"command", "bind"},
                                   {"yaml",
                                    "{name: brake, subject: 9, class: hrt, period: 10ms, reaction_time: 5ms, "
                                    "publishers: [lan], subscribers: [viz]}"}});
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

// cosmicctl replay's requests (control_replay.cpp): each malformed one is refused before anything is
// read or added, and the gateway keeps its segments.
TEST_F(ControlTest, BadReplayRequestsAreRefusedAndAddNoSegment) {
  serve();
  Client client(socket_path);
  const auto code = [&](const Json& request) { return client.call(request)["error"]["code"].get<std::string>(); };
  EXPECT_EQ(code({{"command", "replay"}}), "bad_request");
  EXPECT_EQ(code({{"command", "replay"}, {"segment", {{"file", "relative.mcap"}}}}), "bad_request");
  EXPECT_EQ(code({{"command", "replay"}, {"segment", {{"file", "/r.mcap"}, {"type", "dds"}}}}), "bad_request");
  EXPECT_EQ(code({{"command", "replay"}, {"segment", {{"file", "/r.mcap"}}}, {"mode", "instead"}}), "bad_request");
  EXPECT_EQ(code({{"command", "replay"}, {"segment", {{"file", "/r.mcap"}}}, {"mode", 5}}), "bad_request");
  EXPECT_EQ(code({{"command", "replay"}, {"segment", {{"file", "/r.mcap"}}}, {"match_timeout_s", 600}}), "bad_request");
  const Json missing = client.call({{"command", "replay"}, {"segment", {{"file", "/nonexistent/r.mcap"}}}});
  EXPECT_EQ(missing["error"]["code"], "config_error");
  EXPECT_EQ(missing["errors"][0]["path"], "segment.file");
  EXPECT_EQ(code({{"command", "replay_stop"}}), "bad_request");
  const Json unknown = client.call({{"command", "replay_stop"}, {"name", "lidar"}});
  EXPECT_EQ(unknown["error"]["code"], "not_found");
  EXPECT_NE(unknown["error"]["message"].get<std::string>().find("(running: none)"), std::string::npos);
  EXPECT_EQ(client.call({{"command", "segments"}})["segments"].size(), 2u);
}

TEST_F(ControlTest, PermissionsAreCheckedPerCommandClass) {
  AccessPolicy policy;
  policy.may_modify = [](const PeerCredentials&) { return false; };
  serve(policy);
  Client client(socket_path);
  EXPECT_EQ(client.call({{"command", "status"}})["ok"], true);
  EXPECT_EQ(client.call({{"command", "unbind"}, {"name", "speed"}})["error"]["code"], "permission_denied");
  EXPECT_EQ(client.call({{"command", "replay"}, {"segment", {{"file", "/r.mcap"}}}})["error"]["code"],
            "permission_denied");
  EXPECT_NE(gateway.knowledge_base().find_bound("speed"), nullptr);
}

}  // namespace
}  // namespace cosmic::control_test

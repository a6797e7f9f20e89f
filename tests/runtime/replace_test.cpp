// Atomic replacement of bound channels' definitions (Gateway::replace, the control protocol's
// `replace`, cosmicctl bind --replace) over in-memory segments: the replaced set is admitted as a
// whole, a rejection changes nothing, hops that stay keep their endpoints (the channel id the
// adapters carry) and events already queued for subscribers that stay are still sent.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <future>
#include <map>
#include <optional>
#include <thread>
#include <string>

#include "control_fixture.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

// Two sources of `range` (a real sensor on `body`, a simulator on `sim`), a subscriber on `lan`
// and a monitor on `viz`; `tilt` shares nothing with it but the gateway.
constexpr const char* kReplaceConfig = R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: sim, type: dds, domain: 1, latency_bound: 1ms}
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: wheel, subject: 0x13, class: nrt, payload: 4B, publishers: [body], subscribers: [viz]}
  - {name: range, subject: 0x10, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, publishers: [body], subscribers: [lan, viz]}
  - {name: tilt, subject: 0x11, class: nrt, payload: 4B, publishers: [viz], subscribers: [lan]}
)";

constexpr const char* kRangeFromSim =
    "{name: range, subject: 0x10, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, "
    "publishers: [sim], subscribers: [lan, viz]}";

class QuietLog final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override { lines.emplace_back(message); }
  std::vector<std::string> lines;
};

class ReplaceTest : public ::testing::Test {
 protected:
  ReplaceTest()
      : gateway(
            [this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
              auto adapter = std::make_unique<MemoryAdapter>(spec.name);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 0x77) {
    const auto config = parse_config(kReplaceConfig, "test.yaml");
    EXPECT_TRUE(config.ok()) << (config.errors.empty() ? "" : config.errors[0].to_string());
    EXPECT_TRUE(gateway.start(config.config).applied);
  }
  ~ReplaceTest() override {
    for (auto& [name, adapter] : adapters) adapter->hold_sends(false);  // a failed test must not leave a lane held
    gateway.stop();
  }

  std::vector<ChannelSpec> channels(const std::string& text) {
    auto result = parse_channels(text, "replace.yaml", gateway.config());
    EXPECT_TRUE(result.ok()) << (result.errors.empty() ? "" : result.errors[0].to_string());
    return result.channels;
  }

  // The channel id segment `segment`'s adapter carries `channel` under, in `role` (0: not carried).
  ChannelId carried_id(const std::string& segment, const std::string& channel, HopRole role) {
    for (const auto& b : adapters[segment]->bindings()) {
      if (b.spec.name == channel && b.role == role) return b.id;
    }
    return kNoChannel;
  }

  // Everything the gateway shows about its bindings, to compare before and after.
  std::string state() {
    std::string out;
    for (const auto& c : gateway.admission().channels) {
      out += c.name + " " + to_string(c.verdict) + ":";
      for (const auto& hop : c.hops) out += " " + hop.segment + "/" + to_string(hop.role);
      if (const auto etag = gateway.knowledge_base().etag_of(c.name)) out += " etag " + std::to_string(*etag);
      out += "\n";
    }
    for (const auto& [name, adapter] : adapters) {
      for (const auto& b : adapter->bindings())
        out += name + " carries " + b.spec.name + "#" + std::to_string(b.id) + "\n";
    }
    return out;
  }

  std::size_t sent_of(const std::string& segment, const std::string& channel) {
    std::size_t n = 0;
    for (const auto& e : adapters[segment]->sent()) n += e.channel == channel;
    return n;
  }

  QuietLog log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway;
};

TEST_F(ReplaceTest, MovesThePublisherAndKeepsTheSubscribersEndpoints) {
  const ChannelId lan_before = carried_id("lan", "range", HopRole::subscriber);
  const ChannelId viz_before = carried_id("viz", "range", HopRole::subscriber);
  ASSERT_NE(lan_before, kNoChannel);
  ASSERT_TRUE(gateway.knowledge_base().etag_of("range").has_value());

  const BindResult result = gateway.replace(channels(kRangeFromSim));
  ASSERT_TRUE(result.applied) << result.error;
  ASSERT_EQ(result.replaced.size(), 1u);
  EXPECT_EQ(result.replaced[0].before.publishers, std::vector<std::string>{"body"});
  ASSERT_EQ(result.replaced[0].changes.size(), 1u);
  EXPECT_EQ(result.replaced[0].changes[0], "publishers: [body] -> [sim]");

  // The subscribers' bindings are the same channel id: their endpoints were not recreated.
  EXPECT_EQ(carried_id("lan", "range", HopRole::subscriber), lan_before);
  EXPECT_EQ(carried_id("viz", "range", HopRole::subscriber), viz_before);
  EXPECT_EQ(carried_id("sim", "range", HopRole::publisher), lan_before);
  EXPECT_EQ(carried_id("body", "range", HopRole::publisher), kNoChannel);
  // No CAN hop is left, so the etag is freed; the definition is the new one.
  EXPECT_FALSE(gateway.knowledge_base().etag_of("range").has_value());
  EXPECT_EQ(gateway.knowledge_base().find_bound("range")->publishers, std::vector<std::string>{"sim"});

  ASSERT_TRUE(adapters["sim"]->inject("range", {1, 2, 3, 4}));
  EXPECT_EQ(adapters["lan"]->wait_sent(1, 5s), 1u);
  EXPECT_FALSE(adapters["body"]->inject("range", {9, 9, 9, 9}));  // no longer carried there

  // And back to the CAN sensor, still under the same id.
  const BindResult back = gateway.replace(channels(
      "{name: range, subject: 0x10, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, "
      "publishers: [body], subscribers: [lan, viz]}"));
  ASSERT_TRUE(back.applied) << back.error;
  EXPECT_EQ(carried_id("body", "range", HopRole::publisher), lan_before);
  EXPECT_EQ(carried_id("lan", "range", HopRole::subscriber), lan_before);
  ASSERT_TRUE(adapters["body"]->inject("range", {5, 6, 7, 8}));
  EXPECT_EQ(adapters["lan"]->wait_sent(2, 5s), 2u);
}

// A CAN device that learned the etag through GET_ETAG keeps using it: a replacement that keeps a
// CAN hop keeps the etag even where a fresh allocation would hand out another (here the higher
// one wheel freed).
TEST_F(ReplaceTest, AReplacedChannelKeepsItsEtag) {
  const auto etag = gateway.knowledge_base().etag_of("range");
  ASSERT_TRUE(etag.has_value());
  ASSERT_GT(*gateway.knowledge_base().etag_of("wheel"), *etag);
  ASSERT_TRUE(gateway.unbind("wheel"));
  const BindResult result = gateway.replace(channels(
      "{name: range, subject: 0x10, class: srt, period: 20ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, "
      "publishers: [body], subscribers: [lan, viz]}"));
  ASSERT_TRUE(result.applied) << result.error;
  EXPECT_EQ(gateway.knowledge_base().etag_of("range"), etag);
  EXPECT_EQ(result.replaced.at(0).changes, std::vector<std::string>{"period: 10 ms -> 20 ms"});
}

TEST_F(ReplaceTest, ARejectedReplacementChangesNothing) {
  const std::string before = state();
  // An HRT reaction time the DDS hops alone exceed: admission rejects it.
  const BindResult result = gateway.replace(channels(
      "{name: range, subject: 0x10, class: hrt, period: 10ms, reaction_time: 100us, omission_degree: 1, payload: 4B, "
      "publishers: [sim], subscribers: [lan]}"));
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 1u);
  EXPECT_EQ(result.channels[0].verdict, Verdict::rejected);
  EXPECT_EQ(state(), before);
  EXPECT_EQ(gateway.knowledge_base().find_bound("range")->publishers, std::vector<std::string>{"body"});
  ASSERT_TRUE(adapters["body"]->inject("range", {1, 2, 3, 4}));
  EXPECT_EQ(adapters["lan"]->wait_sent(1, 5s), 1u);
}

TEST_F(ReplaceTest, AChannelThatIsNotBoundRejectsTheWholeReplacement) {
  const std::string before = state();
  const BindResult result =
      gateway.replace(channels(std::string("[") + kRangeFromSim +
                               ", {name: pitch, subject: 0x12, class: nrt, payload: 4B, publishers: [viz], "
                               "subscribers: [lan]}]"));
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 2u);
  EXPECT_NE(result.channels[1].reasons.at(0).find("pitch is not bound"), std::string::npos)
      << result.channels[1].reasons[0];
  EXPECT_NE(result.channels[0].reasons.at(0).find("not replaced"), std::string::npos);
  EXPECT_EQ(state(), before);
  EXPECT_EQ(gateway.knowledge_base().find_bound("pitch"), nullptr);
}

// Each new definition is judged against the set it will be part of: swapping two channels'
// subjects is refused one at a time (the other still holds the subject) and admitted together.
TEST_F(ReplaceTest, TheReplacedSetIsAdmittedAsAWhole) {
  const std::string range_with_tilts_subject =
      "{name: range, subject: 0x11, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, "
      "publishers: [body], subscribers: [lan, viz]}";
  const std::string tilt_with_ranges_subject =
      "{name: tilt, subject: 0x10, class: nrt, payload: 4B, publishers: [viz], subscribers: [lan]}";
  const BindResult alone = gateway.replace(channels(range_with_tilts_subject));
  EXPECT_FALSE(alone.applied);
  EXPECT_NE(alone.channels.at(0).reasons.at(0).find("subject already carried by bound channel tilt"),
            std::string::npos);

  const BindResult together =
      gateway.replace(channels("[" + range_with_tilts_subject + ", " + tilt_with_ranges_subject + "]"));
  ASSERT_TRUE(together.applied) << together.error;
  EXPECT_EQ(gateway.knowledge_base().find_bound("range")->subject, 0x11u);
  EXPECT_EQ(gateway.knowledge_base().find_bound("tilt")->subject, 0x10u);
  ASSERT_EQ(together.replaced.size(), 2u);
  EXPECT_EQ(together.replaced[1].changes.at(0), "subject: 0x0000000000000011 -> 0x0000000000000010");
}

// Events the router has already taken for a subscriber that stays are the channel's own traffic:
// they go out after the switch instead of being discarded with the old route.
TEST_F(ReplaceTest, EventsQueuedForASubscriberThatStaysAreSent) {
  adapters["lan"]->hold_sends(true);
  // Three at once: what range's rate bucket lets through in a bunch (its period and the
  // publisher segment's latency bound; router_policing tests), so policing drops none.
  constexpr std::uint8_t kQueued = 3;
  for (std::uint8_t i = 0; i < kQueued; ++i) ASSERT_TRUE(adapters["body"]->inject("range", {i, 0, 0, 0}));
  // viz has them all, so the router has queued them for lan too, whose lane is blocked in the
  // first send; the rest wait in its queue.
  ASSERT_EQ(adapters["viz"]->wait_sent(kQueued, 5s), kQueued);
  const BindResult result = gateway.replace(channels(
      "{name: range, subject: 0x10, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, payload: 4B, "
      "publishers: [sim], subscribers: [lan]}"));
  ASSERT_TRUE(result.applied) << result.error;
  adapters["lan"]->hold_sends(false);
  EXPECT_EQ(adapters["lan"]->wait_sent(kQueued, 5s), kQueued);
  ASSERT_TRUE(adapters["sim"]->inject("range", {7, 0, 0, 0}));
  EXPECT_EQ(adapters["lan"]->wait_sent(kQueued + 1, 5s), kQueued + 1u);
  EXPECT_EQ(sent_of("viz", "range"), kQueued);  // viz no longer subscribes
  const auto sent = adapters["lan"]->sent();
  ASSERT_EQ(sent.size(), kQueued + 1u);
  for (std::uint8_t i = 0; i < kQueued; ++i) EXPECT_EQ(sent[i].payload[0], i);
  EXPECT_EQ(sent[kQueued].payload[0], 7);
}

// Sequence numbers the gateway stamps go on across a replacement: a receiver's duplicate
// window would take restarted numbers for copies of events it already has.
TEST_F(ReplaceTest, TheGatewaysSequenceNumbersGoOn) {
  ASSERT_TRUE(adapters["body"]->inject("range", {1, 0, 0, 0}));
  ASSERT_EQ(adapters["lan"]->wait_sent(1, 5s), 1u);
  ASSERT_TRUE(gateway.replace(channels(kRangeFromSim)).applied);
  ASSERT_TRUE(adapters["sim"]->inject("range", {2, 0, 0, 0}));
  ASSERT_EQ(adapters["lan"]->wait_sent(2, 5s), 2u);
  const auto sent = adapters["lan"]->sent();
  EXPECT_EQ(sent[1].header.origin, sent[0].header.origin);
  EXPECT_GT(sent[1].header.sequence, sent[0].header.sequence);
}

TEST_F(ReplaceTest, ARefusingTransportUndoesTheReplacement) {
  const std::string before = state();
  adapters["sim"]->refuse_channel("range", "no such topic");
  const BindResult result = gateway.replace(channels(kRangeFromSim));
  EXPECT_FALSE(result.applied);
  EXPECT_NE(result.error.find("segment sim does not carry channel range: no such topic"), std::string::npos)
      << result.error;
  EXPECT_EQ(state(), before);
}

// --- made before break (issue 40): the new publisher hop opens first, the old source feeds the
// channel until it has matched a writer (or the match timeout passes), then the switch.

bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

TEST_F(ReplaceTest, MadeBeforeBreakTheOldSourceFeedsUntilTheNewOneHasMatched) {
  adapters["sim"]->simulate_discovery();
  auto replacing = std::async(std::launch::async, [&] { return gateway.replace(channels(kRangeFromSim), 20s); });
  // The simulator's hop is open beside the CAN sensor's before the switch.
  ASSERT_TRUE(eventually([&] { return carried_id("sim", "range", HopRole::publisher) != kNoChannel; }, 5000ms));
  EXPECT_NE(carried_id("body", "range", HopRole::publisher), kNoChannel);
  // Until it matches, the CAN sensor feeds the channel; what the simulator sends goes nowhere.
  ASSERT_TRUE(adapters["body"]->inject("range", {1, 1, 1, 1}));
  EXPECT_EQ(adapters["lan"]->wait_sent(1, 5s), 1u);
  ASSERT_TRUE(adapters["sim"]->inject("range", {2, 2, 2, 2}));
  EXPECT_EQ(replacing.wait_for(100ms), std::future_status::timeout) << "switched before the new publisher matched";

  adapters["sim"]->set_matched("range", 1);
  ASSERT_EQ(replacing.wait_for(10s), std::future_status::ready);
  const BindResult result = replacing.get();
  ASSERT_TRUE(result.applied) << result.error;
  EXPECT_FALSE(result.match_timed_out);
  ASSERT_EQ(result.new_publishers.size(), 1u);
  EXPECT_EQ(result.new_publishers[0].channel, "range");
  EXPECT_EQ(result.new_publishers[0].segment, "sim");
  EXPECT_EQ(result.new_publishers[0].matched, std::optional<std::size_t>(1));
  EXPECT_GE(result.switch_wait, std::chrono::milliseconds(100));
  EXPECT_EQ(carried_id("body", "range", HopRole::publisher), kNoChannel);
  EXPECT_FALSE(adapters["body"]->inject("range", {9, 9, 9, 9}));
  ASSERT_TRUE(adapters["sim"]->inject("range", {3, 3, 3, 3}));
  ASSERT_EQ(adapters["lan"]->wait_sent(2, 5s), 2u);
  const auto sent = adapters["lan"]->sent();
  EXPECT_EQ(sent[0].payload, (std::vector<std::uint8_t>{1, 1, 1, 1}));
  EXPECT_EQ(sent[1].payload, (std::vector<std::uint8_t>{3, 3, 3, 3}));
}

TEST_F(ReplaceTest, AtTheMatchTimeoutItSwitchesAndSaysNoWriterMatched) {
  adapters["sim"]->simulate_discovery();
  const BindResult result = gateway.replace(channels(kRangeFromSim), 60ms);
  ASSERT_TRUE(result.applied) << result.error;
  EXPECT_TRUE(result.match_timed_out);
  ASSERT_EQ(result.new_publishers.size(), 1u);
  EXPECT_EQ(result.new_publishers[0].matched, std::optional<std::size_t>(0));
  EXPECT_GE(result.switch_wait, std::chrono::milliseconds(60));
  EXPECT_EQ(carried_id("body", "range", HopRole::publisher), kNoChannel);
  EXPECT_NE(carried_id("sim", "range", HopRole::publisher), kNoChannel);
}

TEST_F(ReplaceTest, WithoutDiscoveryTheSwitchDoesNotWait) {
  const BindResult result = gateway.replace(channels(kRangeFromSim), 20s);
  ASSERT_TRUE(result.applied) << result.error;
  EXPECT_FALSE(result.match_timed_out);
  ASSERT_EQ(result.new_publishers.size(), 1u);
  EXPECT_EQ(result.new_publishers[0].matched, std::nullopt);  // nothing to wait for: LCM, CAN
  EXPECT_LT(result.switch_wait, 5s);
}

TEST_F(ReplaceTest, ANewHopTheTransportRefusesIsClosedAgainWithoutWaiting) {
  const std::string before = state();
  adapters["sim"]->simulate_discovery();
  adapters["sim"]->refuse_channel("range", "no such topic");
  auto replacing = std::async(std::launch::async, [&] { return gateway.replace(channels(kRangeFromSim), 60s); });
  ASSERT_EQ(replacing.wait_for(30s), std::future_status::ready) << "waited for a hop that was refused";
  const BindResult result = replacing.get();
  EXPECT_FALSE(result.applied);
  EXPECT_NE(result.error.find("segment sim does not carry channel range: no such topic"), std::string::npos)
      << result.error;
  EXPECT_EQ(state(), before);
}

// A rejected replacement opens nothing: no hop appears anywhere, however long it could wait.
TEST_F(ReplaceTest, ARejectedReplacementOpensNoHop) {
  adapters["sim"]->simulate_discovery();
  const std::string before = state();
  const BindResult result = gateway.replace(channels("{name: range, subject: 0x10, class: srt, period: 10ms, "
                                                     "reaction_time: 20ms, omission_degree: 1, payload: 4KiB, "
                                                     "publishers: [sim], subscribers: [lan, body]}"),
                                            60s);
  EXPECT_FALSE(result.applied);
  EXPECT_EQ(state(), before);
  EXPECT_EQ(carried_id("sim", "range", HopRole::publisher), kNoChannel);
}

}  // namespace

// The control protocol's `replace`: the answer says what changed per channel and which hops stay.
namespace control_test {
namespace {

TEST_F(ControlTest, ReplaceAnswersWhatChangedAndWhichHopsStay) {
  serve();
  Client client(socket_path);
  const Json answer = client.call({{"command", "replace"},
                                   {"yaml",
                                    "{name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, "
                                    "omission_degree: 2, publishers: [viz], subscribers: [lan]}"}});
  ASSERT_EQ(answer["ok"], true) << answer.dump();
  ASSERT_EQ(answer["replaced"].size(), 1u);
  const Json& speed = answer["replaced"][0];
  EXPECT_EQ(speed["name"], "speed");
  EXPECT_EQ(speed["changes"],
            Json::array({"omission_degree: 1 -> 2", "publishers: [lan] -> [viz]", "subscribers: [viz] -> [lan]"}));
  EXPECT_TRUE(speed["hops"]["kept"].empty());
  EXPECT_EQ(speed["hops"]["added"].size(), 2u);
  EXPECT_EQ(speed["hops"]["removed"].size(), 2u);

  const Json same =
      client.call({{"command", "replace"},
                   {"yaml",
                    "{name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, "
                    "publishers: [viz], subscribers: [lan]}"}});
  ASSERT_EQ(same["ok"], true) << same.dump();
  EXPECT_EQ(same["replaced"][0]["hops"]["kept"].size(), 2u);
}

// Made before break over the socket: the answer comes once the new publisher matched (the wait
// runs on the server's worker, the control thread answers meanwhile) or at the match timeout.
// The control tests' configuration with a simulator's DDS domain: `speed` does not use it yet.
constexpr const char* kWithSim = R"(
gateway: {name: gw}
segments:
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
  - {name: sim, type: dds, domain: 1, latency_bound: 1ms}
channels:
  - {name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}
)";

class SwitchOverTest : public ControlTest {
 protected:
  SwitchOverTest() : ControlTest(kWithSim) {}
};

TEST_F(SwitchOverTest, ReplaceWaitsForTheNewPublisherToMatchThenSaysSo) {
  Setup setup;
  setup.admission = Admission::server_worker;
  serve_with(setup);
  Client client(socket_path);
  adapters["sim"]->simulate_discovery();
  const std::string from_sim =
      "{name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [sim], "
      "subscribers: [viz]}";
  const std::string from_lan =
      "{name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], "
      "subscribers: [viz]}";
  const Json timed_out = client.call({{"command", "replace"}, {"yaml", from_sim}, {"match_timeout_s", 0.05}});
  ASSERT_EQ(timed_out["ok"], true) << timed_out.dump();
  const Json& switched = timed_out["switch_over"];
  EXPECT_EQ(switched["timed_out"], true);
  EXPECT_GE(switched["waited_s"].get<double>(), 0.05);
  EXPECT_DOUBLE_EQ(switched["match_timeout_s"].get<double>(), 0.05);
  EXPECT_EQ(switched["publishers"], Json::array({{{"channel", "speed"}, {"segment", "sim"}, {"matched", 0}}}));

  // Back to lan, then to sim again once a writer there has matched: no timeout.
  ASSERT_EQ(client.call({{"command", "replace"}, {"yaml", from_lan}})["ok"], true);
  client.send_raw(Json{{"command", "replace"}, {"yaml", from_sim}, {"match_timeout_s", 30}}.dump() + "\n");
  // While the switch waits, the control thread answers reads; changes are busy.
  Client other(socket_path);
  ASSERT_TRUE(eventually(
      [&] {
        const Json busy = other.call({{"command", "unbind"}, {"name", "speed"}});
        return busy["error"]["code"] == "busy" &&
               busy["error"]["message"].get<std::string>().find("waiting up to 30 s for its new publishers to match") !=
                   std::string::npos;
      },
      5000ms));
  EXPECT_EQ(other.call({{"command", "status"}})["ok"], true);
  EXPECT_EQ(gateway.knowledge_base().find_bound("speed")->publishers, std::vector<std::string>{"lan"});
  adapters["sim"]->set_matched("speed", 2);
  const Json matched = Json::parse(client.read_line(), nullptr, false);
  ASSERT_EQ(matched["ok"], true) << matched.dump();
  EXPECT_EQ(matched["switch_over"]["timed_out"], false);
  EXPECT_EQ(matched["switch_over"]["publishers"][0]["matched"], 2);
  EXPECT_LT(matched["switch_over"]["waited_s"].get<double>(), 30.0);
}

TEST_F(ControlTest, ReplaceWithABadMatchTimeoutIsRefusedAndChangesNothing) {
  serve();
  Client client(socket_path);
  const std::string yaml =
      "{name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [viz], "
      "subscribers: [lan]}";
  for (const Json& bad : {Json(-1), Json(61), Json("5s"), Json(nullptr)}) {
    const Json answer = client.call({{"command", "replace"}, {"yaml", yaml}, {"match_timeout_s", bad}});
    EXPECT_EQ(answer["ok"], false) << bad.dump();
    EXPECT_EQ(answer["error"]["code"], "bad_request") << bad.dump();
    EXPECT_NE(answer["error"]["message"].get<std::string>().find("match_timeout_s"), std::string::npos);
  }
  EXPECT_EQ(gateway.knowledge_base().find_bound("speed")->publishers, std::vector<std::string>{"lan"});
}

TEST_F(ControlTest, ReplaceOfAChannelThatIsNotBoundIsNotFoundAndChangesNothing) {
  serve();
  Client client(socket_path);
  const Json answer =
      client.call({{"command", "replace"},
                   {"yaml", "{name: nope, subject: 9, class: nrt, publishers: [lan], subscribers: [viz]}"}});
  EXPECT_EQ(answer["ok"], false);
  EXPECT_EQ(answer["error"]["code"], "not_found");
  EXPECT_NE(answer["error"]["message"].get<std::string>().find("'nope'"), std::string::npos);
  EXPECT_EQ(client.call({{"command", "channel"}, {"name", "nope"}})["error"]["code"], "not_found");
}

}  // namespace
}  // namespace control_test
}  // namespace cosmic

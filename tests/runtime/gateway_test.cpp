// The gateway runtime over in-memory segments: binding through admission, runtime bind/unbind
// while traffic flows, reload keeping what did not change.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <thread>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

class NullLogger final : public Logger {
 public:
  void log(LogLevel level, std::string_view message) override {
    lines.emplace_back(message);
    levels.push_back(level);
  }
  // Lines containing `text` logged at `level`.
  std::size_t count(std::string_view text, LogLevel level) const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) n += levels[i] == level && lines[i].find(text) != std::string::npos;
    return n;
  }
  std::vector<std::string> lines;
  std::vector<LogLevel> levels;
};

constexpr const char* kConfig = R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}
  - {name: log, subject: 2, class: nrt, publishers: [viz], subscribers: [lan]}
)";

class GatewayTest : public ::testing::Test {
 protected:
  GatewayTest()
      : gateway(
            [this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
              auto adapter = std::make_unique<MemoryAdapter>(spec.name);
              for (const auto& [channel, reason] : refuse_at_creation[spec.name])
                adapter->refuse_channel(channel, reason);
              adapter->fail_configure(fail_at_creation[spec.name]);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 0x1234) {}

  Config parse(const std::string& text) {
    auto result = parse_config(text, "test.yaml");
    EXPECT_TRUE(result.ok()) << (result.errors.empty() ? "" : result.errors[0].to_string());
    return result.config;
  }

  std::vector<ChannelSpec> channels(const std::string& text) {
    auto result = parse_channels(text, "bind.yaml", gateway.config());
    EXPECT_TRUE(result.ok()) << (result.errors.empty() ? "" : result.errors[0].to_string());
    return result.channels;
  }

  void expect_flow(const std::string& channel, const std::string& from, const std::string& to) {
    const std::size_t before = adapters[to]->sent().size();
    ASSERT_TRUE(adapters[from]->inject(channel, {1, 2}));
    EXPECT_EQ(adapters[to]->wait_sent(before + 1, std::chrono::seconds(5)), before + 1);
  }

  const ChannelReport* verdict_of(const std::string& channel) {
    report_ = gateway.admission();
    return report_.find(channel);
  }

  // The channel shows admission's own verdict (bound or degraded), nothing refused.
  void expect_carried(const std::string& channel) {
    const ChannelReport* shown = verdict_of(channel);
    const AdmissionReport admitted = gateway.knowledge_base().report();
    ASSERT_NE(shown, nullptr) << channel;
    ASSERT_NE(admitted.find(channel), nullptr) << channel;
    EXPECT_NE(shown->verdict, Verdict::failed) << channel;
    EXPECT_EQ(shown->verdict, admitted.find(channel)->verdict) << channel;
    EXPECT_FALSE(has_reason(*shown, "does not carry")) << channel;
  }

  static bool has_reason(const ChannelReport& report, const std::string& text) {
    for (const auto& reason : report.reasons) {
      if (reason.find(text) != std::string::npos) return true;
    }
    return false;
  }

  NullLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  // Set before start(): what each segment's adapter refuses from its creation on.
  std::map<std::string, std::map<std::string, std::string>> refuse_at_creation;  // segment -> channel -> reason
  std::map<std::string, std::string> fail_at_creation;                           // segment -> reason
  AdmissionReport report_;
  Gateway gateway;
};

TEST_F(GatewayTest, StartBindsEveryAdmittedChannelAndForwards) {
  const auto result = gateway.start(parse(kConfig));
  ASSERT_TRUE(result.applied);
  ASSERT_EQ(result.channels.size(), 2u);
  EXPECT_EQ(result.channels[0].verdict, Verdict::bound);
  expect_flow("speed", "lan", "viz");
  expect_flow("log", "viz", "lan");
  EXPECT_EQ(adapters["lan"]->bindings().size(), 2u);
}

// Issue 20, item 1: the rate bucket banks what the publisher segment's latency bound allows,
// 1 + ceil(500 ms / 100 ms) = 6 events here (the gateway's floor is 3): six events bunched at
// once pass, the seventh and eighth are cut.
TEST_F(GatewayTest, RatePolicingBanksTheJitterOfThePublisherSegment) {
  const auto result = gateway.start(parse(R"(
gateway: {name: gw}
segments:
  - {name: slow, type: lcm, url: "udpm://239.255.76.67:7700?ttl=0", latency_bound: 500ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: beacon, subject: 9, class: nrt, period: 100ms, publishers: [slow], subscribers: [viz]}
)"));
  ASSERT_TRUE(result.applied);
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(adapters["slow"]->inject("beacon", {1, 2}));
  const auto rate_drops = [&] {
    for (const auto& c : gateway.channel_stats()) {
      if (c.name != "beacon") continue;
      std::uint64_t n = 0;
      for (const auto& s : c.segments) n += s.dropped[static_cast<std::size_t>(DropReason::rate)];
      return n;
    }
    return std::uint64_t{0};
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (rate_drops() < 2 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(rate_drops(), 2u);
  EXPECT_EQ(adapters["viz"]->wait_sent(6, std::chrono::seconds(5)), 6u);
}

TEST_F(GatewayTest, RejectedRuntimeBindChangesNothing) {
  gateway.start(parse(kConfig));
  // HRT over LCM (no real-time guarantee, no retransmission): rejected.
  const auto result =
      gateway.bind(channels("{name: brake, subject: 9, class: hrt, period: 10ms, reaction_time: 5ms, publishers: "
                            "[lan], subscribers: [viz]}"));
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 1u);
  EXPECT_EQ(result.channels[0].verdict, Verdict::rejected);
  bool mentions_realtime = false;
  for (const auto& reason : result.channels[0].reasons)
    mentions_realtime |= reason.find("real-time") != std::string::npos;
  EXPECT_TRUE(mentions_realtime);
  EXPECT_EQ(gateway.knowledge_base().bound_channels().size(), 2u);
  EXPECT_EQ(adapters["viz"]->bindings().size(), 2u);
  expect_flow("speed", "lan", "viz");
}

TEST_F(GatewayTest, BindIsAllOrNothing) {
  gateway.start(parse(kConfig));
  const auto result = gateway.bind(channels(R"(
channels:
  - {name: ok, subject: 10, class: nrt, publishers: [lan], subscribers: [viz]}
  - {name: bad, subject: 11, class: hrt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [viz]}
)"));
  EXPECT_FALSE(result.applied);
  EXPECT_EQ(gateway.knowledge_base().find_bound("ok"), nullptr);
}

TEST_F(GatewayTest, RuntimeBindAndUnbindWhileTrafficFlows) {
  gateway.start(parse(kConfig));
  expect_flow("speed", "lan", "viz");
  ASSERT_TRUE(
      gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}")).applied);
  expect_flow("extra", "lan", "viz");
  expect_flow("speed", "lan", "viz");
  EXPECT_TRUE(gateway.unbind("extra"));
  EXPECT_FALSE(adapters["lan"]->inject("extra", {1}));
  EXPECT_FALSE(gateway.unbind("extra"));
  expect_flow("speed", "lan", "viz");
  const auto stats = gateway.channel_stats();
  ASSERT_EQ(stats.size(), 2u);
  for (const auto& s : stats) {
    if (s.name == "speed") {
      EXPECT_EQ(s.forwarded, 3u);  // nothing lost across bind/unbind
    }
  }
}

TEST_F(GatewayTest, ReloadKeepsUnchangedChannelsAndAddsNewOnes) {
  gateway.start(parse(kConfig));
  expect_flow("speed", "lan", "viz");
  MemoryAdapter* lan_before = adapters["lan"];
  std::string next = kConfig;
  next += "  - {name: extra, subject: 3, class: nrt, publishers: [lan], subscribers: [viz]}\n";
  ASSERT_TRUE(gateway.reload(parse(next)).applied);
  EXPECT_EQ(adapters["lan"], lan_before);  // unchanged segment keeps its adapter
  expect_flow("extra", "lan", "viz");
  expect_flow("speed", "lan", "viz");
  const auto stats = gateway.channel_stats();
  for (const auto& s : stats) {
    if (s.name == "speed") {
      EXPECT_EQ(s.forwarded, 2u);  // counters survived the reload
    }
  }
}

TEST_F(GatewayTest, ReloadWithChangedSegmentReplacesItsAdapter) {
  gateway.start(parse(kConfig));
  MemoryAdapter* viz_before = adapters["viz"];
  std::string next = kConfig;
  next.replace(next.find("latency_bound: 2ms"), 18, "latency_bound: 3ms");
  ASSERT_TRUE(gateway.reload(parse(next)).applied);
  EXPECT_NE(adapters["viz"], viz_before);
  expect_flow("speed", "lan", "viz");
}

TEST_F(GatewayTest, SegmentSlotsStayDistinctAcrossReloads) {
  gateway.start(parse(kConfig));
  std::string changed = kConfig;
  changed.replace(changed.find("latency_bound: 2ms"), 18, "latency_bound: 3ms");  // viz moves to a new slot
  ASSERT_TRUE(gateway.reload(parse(changed)).applied);
  std::string grown = changed;
  grown.replace(grown.find("channels:"), 9, R"(  - {name: x, type: lcm, url: "udpm://239.255.76.67:7001?ttl=0"}
  - {name: y, type: lcm, url: "udpm://239.255.76.67:7002?ttl=0"}
channels:
  - {name: to-x, subject: 20, class: nrt, publishers: [lan], subscribers: [x]}
  - {name: to-y, subject: 21, class: nrt, publishers: [lan], subscribers: [y]})");
  ASSERT_TRUE(gateway.reload(parse(grown)).applied);
  expect_flow("speed", "lan", "viz");
  expect_flow("to-x", "lan", "x");
  expect_flow("to-y", "lan", "y");
  for (const char* segment : {"viz", "x", "y"}) {
    for (const auto& sent : adapters[segment]->sent()) {
      EXPECT_EQ(sent.channel, std::string(segment) == "viz" ? "speed" : std::string("to-") + segment) << segment;
    }
  }
}

TEST_F(GatewayTest, SegmentHealthDegradesItsChannels) {
  gateway.start(parse(kConfig));
  adapters["viz"]->set_health(SegmentHealth::down, "interface gone");
  gateway.refresh_health();
  const auto report = gateway.admission();
  ASSERT_NE(report.find("speed"), nullptr);
  EXPECT_EQ(report.find("speed")->verdict, Verdict::degraded);
  EXPECT_FALSE(gateway.all_segments_up());
}

// Issue 9, item 10: a channel a segment's transport refuses (configure) is `failed` with the
// transport's reason, never `bound` and silent.
TEST_F(GatewayTest, AChannelItsSegmentRefusesAtStartIsFailedWithTheReason) {
  refuse_at_creation["viz"]["speed"] = "LCM channel names have at most 63 characters";
  const auto result = gateway.start(parse(kConfig));
  ASSERT_TRUE(result.applied);
  ASSERT_EQ(result.channels.size(), 2u);
  EXPECT_EQ(result.channels[0].name, "speed");
  EXPECT_EQ(result.channels[0].verdict, Verdict::failed);
  EXPECT_TRUE(
      has_reason(result.channels[0], "segment viz does not carry it: LCM channel names have at most 63 characters"));
  EXPECT_EQ(result.channels[1].name, "log");
  EXPECT_NE(result.channels[1].verdict, Verdict::failed);
  // What cosmicctl channels shows (admission()) says the same, and the log has one error line.
  const ChannelReport* speed = verdict_of("speed");
  ASSERT_NE(speed, nullptr);
  EXPECT_EQ(speed->verdict, Verdict::failed);
  EXPECT_TRUE(has_reason(*speed, "segment viz does not carry it"));
  expect_carried("log");
  EXPECT_EQ(log.count("channel speed: segment viz does not carry it: LCM channel names have at most 63 characters",
                      LogLevel::error),
            1u);
  // Admitted all the same: its reservation is held, so a later configuration can carry it.
  EXPECT_NE(gateway.knowledge_base().find_bound("speed"), nullptr);
  // The other channel flows; speed's other segment still has it.
  expect_flow("log", "viz", "lan");
  EXPECT_EQ(adapters["lan"]->bindings().size(), 2u);
  EXPECT_EQ(adapters["viz"]->bindings().size(), 1u);
}

TEST_F(GatewayTest, ARefusalIsLoggedOnceAndItsEndIsLoggedAndShown) {
  refuse_at_creation["viz"]["speed"] = "no room";
  gateway.start(parse(kConfig));
  // Other changes reconfigure every segment: the refusal stays visible, logged once.
  ASSERT_TRUE(
      gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}")).applied);
  EXPECT_TRUE(gateway.unbind("extra"));
  EXPECT_EQ(verdict_of("speed")->verdict, Verdict::failed);
  EXPECT_EQ(log.count("channel speed: segment viz does not carry it: no room", LogLevel::error), 1u);
  // A new reason is a new line.
  adapters["viz"]->refuse_channel("speed", "still no room");
  ASSERT_TRUE(
      gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}")).applied);
  EXPECT_EQ(log.count("channel speed: segment viz does not carry it: still no room", LogLevel::error), 1u);
  // The transport takes it at the next configuration: bound again, said once, and it flows.
  adapters["viz"]->refuse_channel("speed", "");
  EXPECT_TRUE(gateway.unbind("extra"));
  expect_carried("speed");
  EXPECT_EQ(verdict_of("speed")->verdict, Verdict::bound);
  EXPECT_EQ(log.count("channel speed: segment viz carries it now", LogLevel::notice), 1u);
  expect_flow("speed", "lan", "viz");
}

TEST_F(GatewayTest, ASegmentFailingAsAWholeFailsEveryChannelItDoesNotCarry) {
  fail_at_creation["lan"] = "DDS segment lan is not started";
  const auto result = gateway.start(parse(kConfig));
  ASSERT_TRUE(result.applied);
  for (const auto& channel : result.channels) {
    EXPECT_EQ(channel.verdict, Verdict::failed) << channel.name;
    EXPECT_TRUE(has_reason(channel, "segment lan does not carry it: DDS segment lan is not started")) << channel.name;
  }
  EXPECT_EQ(log.count("segment lan does not carry it: DDS segment lan is not started", LogLevel::error), 2u);
  // Once it takes its channels, everything is bound; a later whole failure concerns only what it
  // did not carry yet: the new channel of a bind, which is then refused.
  adapters["lan"]->fail_configure("");
  ASSERT_TRUE(
      gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}")).applied);
  expect_carried("speed");
  expect_carried("log");
  adapters["lan"]->fail_configure("cannot create a DataReader on cosmic/more");
  const auto bind =
      gateway.bind(channels("{name: more, subject: 13, class: nrt, publishers: [lan], subscribers: [viz]}"));
  EXPECT_FALSE(bind.applied);
  ASSERT_EQ(bind.channels.size(), 1u);
  EXPECT_EQ(bind.channels[0].verdict, Verdict::failed);
  EXPECT_NE(bind.error.find("segment lan does not carry channel more: cannot create a DataReader on cosmic/more"),
            std::string::npos)
      << bind.error;
  EXPECT_EQ(gateway.knowledge_base().find_bound("more"), nullptr);
  for (const char* name : {"speed", "log", "extra"}) expect_carried(name);
  expect_flow("speed", "lan", "viz");
}

TEST_F(GatewayTest, ABindWhoseChannelASegmentRefusesChangesNothing) {
  gateway.start(parse(kConfig));
  adapters["viz"]->refuse_channel("extra", "LCM channel names have at most 63 characters");
  const auto result = gateway.bind(channels(R"(
channels:
  - {name: fine, subject: 11, class: nrt, publishers: [lan], subscribers: [viz]}
  - {name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}
)"));
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 2u);
  EXPECT_NE(result.channels[0].verdict, Verdict::failed);
  EXPECT_EQ(result.channels[1].verdict, Verdict::failed);
  EXPECT_TRUE(
      has_reason(result.channels[1], "segment viz does not carry it: LCM channel names have at most 63 characters"));
  EXPECT_NE(result.error.find("segment viz does not carry channel extra"), std::string::npos) << result.error;
  EXPECT_NE(result.error.find("nothing changed"), std::string::npos) << result.error;
  EXPECT_EQ(gateway.knowledge_base().find_bound("fine"), nullptr);
  EXPECT_EQ(gateway.knowledge_base().find_bound("extra"), nullptr);
  EXPECT_EQ(adapters["lan"]->bindings().size(), 2u);
  EXPECT_EQ(gateway.admission().channels.size(), 2u);
  for (const char* name : {"speed", "log"}) expect_carried(name);
}

TEST_F(GatewayTest, ARefusalOfABoundChannelDoesNotBlockOtherBinds) {
  refuse_at_creation["viz"]["speed"] = "no room";
  gateway.start(parse(kConfig));
  const auto result =
      gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}"));
  EXPECT_TRUE(result.applied) << result.error;
  EXPECT_NE(result.channels.at(0).verdict, Verdict::failed);
  expect_flow("extra", "lan", "viz");
  EXPECT_EQ(verdict_of("speed")->verdict, Verdict::failed);
}

TEST_F(GatewayTest, ReloadShowsWhatASegmentRefuses) {
  gateway.start(parse(kConfig));
  adapters["viz"]->refuse_channel("extra", "no room");
  std::string next = kConfig;
  next += "  - {name: extra, subject: 3, class: nrt, publishers: [lan], subscribers: [viz]}\n";
  const auto result = gateway.reload(parse(next));
  ASSERT_TRUE(result.applied);
  ASSERT_EQ(result.channels.size(), 3u);
  EXPECT_EQ(result.channels[2].name, "extra");
  EXPECT_EQ(result.channels[2].verdict, Verdict::failed);
  EXPECT_TRUE(has_reason(result.channels[2], "segment viz does not carry it: no room"));
  EXPECT_EQ(verdict_of("extra")->verdict, Verdict::failed);
  EXPECT_EQ(log.count("channel extra: segment viz does not carry it: no room", LogLevel::error), 1u);
  expect_flow("speed", "lan", "viz");
}

}  // namespace
}  // namespace cosmic

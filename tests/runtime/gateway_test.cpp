// The gateway runtime over in-memory segments: binding through admission, runtime bind/unbind
// while traffic flows, reload keeping what did not change.
#include <gtest/gtest.h>

#include <map>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

class NullLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override { lines.emplace_back(message); }
  std::vector<std::string> lines;
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
      : gateway([this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
          auto adapter = std::make_unique<MemoryAdapter>(spec.name);
          adapters[spec.name] = adapter.get();
          return adapter;
        }, log, 0x1234) {}

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

  NullLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
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

TEST_F(GatewayTest, RejectedRuntimeBindChangesNothing) {
  gateway.start(parse(kConfig));
  // HRT over LCM (no real-time guarantee, no retransmission): rejected.
  const auto result = gateway.bind(channels(
      "{name: brake, subject: 9, class: hrt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [viz]}"));
  EXPECT_FALSE(result.applied);
  ASSERT_EQ(result.channels.size(), 1u);
  EXPECT_EQ(result.channels[0].verdict, Verdict::rejected);
  bool mentions_realtime = false;
  for (const auto& reason : result.channels[0].reasons) mentions_realtime |= reason.find("real-time") != std::string::npos;
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
  ASSERT_TRUE(gateway.bind(channels("{name: extra, subject: 12, class: nrt, publishers: [lan], subscribers: [viz]}")).applied);
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

}  // namespace
}  // namespace cosmic

// Reload from the running admission (issue 11): a reload of an unchanged or extended
// configuration starts from what start or the last reload admitted and admits only the new
// channels, and its plan is exactly the plan of admission from scratch; anything else, or a bind
// or unbind in between, admits from scratch.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"
#include "cosmic/report.hpp"

namespace cosmic {
namespace {

class QuietLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

constexpr std::int64_t kMs = 1'000'000;

ChannelSpec channel(const std::string& name, std::uint64_t subject, ChannelClass cls, const std::string& from,
                    const std::string& to, std::uint64_t payload, std::int64_t period_ms) {
  ChannelSpec c;
  c.name = name;
  c.subject = subject;
  c.cls = cls;
  c.payload = payload;
  c.period = Nanos(period_ms * kMs);
  if (cls != ChannelClass::nrt) c.reaction_time = Nanos(period_ms * kMs);
  c.omission_degree = 1;
  c.publishers = {from};
  c.subscribers = {to};
  return c;
}

// A CAN bus loaded enough for priorities, etags and response times to depend on what was bound
// before, a static etag, and IP channels, one of them rejected (HRT over LCM).
Config base_config() {
  const auto parsed = parse_config(R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: bus, type: can, interface: vcan0, bitrate: 125kbit/s}
  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: pinned, subject: 0x77, class: srt, period: 20ms, reaction_time: 20ms, payload: 8B, etag: 150, publishers: [bus], subscribers: [lan]}
)",
                                   "reload.yaml");
  EXPECT_TRUE(parsed.ok()) << (parsed.errors.empty() ? "" : parsed.errors[0].to_string());
  Config config = parsed.config;
  for (int i = 0; i < 40; ++i) {
    const ChannelClass cls = i % 5 == 0 ? ChannelClass::hrt : i % 5 < 3 ? ChannelClass::srt : ChannelClass::nrt;
    config.channels.push_back(
        channel("can" + std::to_string(i), 0x100 + i, cls, "bus", "lan", 1 + i % 8, 20 + 10 * (i % 7)));
  }
  for (int i = 0; i < 20; ++i) {
    config.channels.push_back(channel("ip" + std::to_string(i), 0x200 + i,
                                      i % 2 ? ChannelClass::srt : ChannelClass::nrt, i % 2 ? "lan" : "viz",
                                      i % 2 ? "viz" : "lan", 64, 100));
  }
  config.channels.push_back(channel("estop", 0x300, ChannelClass::hrt, "lan", "viz", 1, 5));  // rejected
  return config;
}

std::string text_of(const std::vector<ChannelReport>& reports) {
  std::string out;
  for (const auto& report : reports) out += to_json(report).dump() + "\n";
  return out;
}

// The plan of admission from scratch and `plan` agree on every verdict and number, in the
// answer (bind-time reports) and in the knowledge base they leave.
void expect_same_as_from_scratch(const ReloadPlan& plan) {
  const ReloadPlan scratch = Gateway::plan_reload(plan.config);
  EXPECT_EQ(scratch.reused, 0u);
  EXPECT_EQ(text_of(plan.reports), text_of(scratch.reports));
  EXPECT_EQ(to_json(plan.kb->report()).dump(), to_json(scratch.kb->report()).dump());
  for (const auto& c : plan.config.channels) EXPECT_EQ(plan.kb->etag_of(c.name), scratch.kb->etag_of(c.name)) << c.name;
  ASSERT_TRUE(plan.admitted);
  EXPECT_EQ(to_json(plan.admitted->kb.report()).dump(), to_json(scratch.kb->report()).dump());
  EXPECT_EQ(text_of(plan.admitted->reports), text_of(scratch.reports));
}

class ReloadPlanTest : public ::testing::Test {
 protected:
  ReloadPlanTest()
      : gateway([](const SegmentSpec& spec, const GatewayIdentity&,
                   Logger&) -> std::unique_ptr<SegmentAdapter> { return std::make_unique<MemoryAdapter>(spec.name); },
                log, 0x42) {}

  QuietLogger log;
  Gateway gateway;
};

TEST_F(ReloadPlanTest, TheSetUnderTestHasRejectionsAndAStaticEtag) {
  const ReloadPlan plan = Gateway::plan_reload(base_config());
  std::size_t rejected = 0;
  for (const auto& report : plan.reports) rejected += report.verdict == Verdict::rejected ? 1 : 0;
  EXPECT_GE(rejected, 1u);
  EXPECT_EQ(plan.kb->etag_of("pinned"), std::optional<std::uint16_t>(150));
}

TEST_F(ReloadPlanTest, AnUnchangedConfigurationIsNotAdmittedAgain) {
  const Config config = base_config();
  ASSERT_TRUE(gateway.start(config).applied);
  const auto base = gateway.reload_base();
  ASSERT_TRUE(base);
  const ReloadPlan plan = Gateway::plan_reload(config, base);
  EXPECT_EQ(plan.reused, config.channels.size());
  EXPECT_EQ(plan.admitted, base);  // nothing new to remember
  expect_same_as_from_scratch(plan);
  ASSERT_TRUE(gateway.commit_reload(plan).applied);
  EXPECT_EQ(gateway.reload_base(), base);
}

TEST_F(ReloadPlanTest, AppendedChannelsAloneAreAdmitted) {
  Config config = base_config();
  ASSERT_TRUE(gateway.start(config).applied);
  const std::size_t before = config.channels.size();
  config.channels.push_back(channel("late_can", 0x400, ChannelClass::hrt, "bus", "lan", 8, 10));  // highest priority
  config.channels.push_back(channel("late_ip", 0x401, ChannelClass::nrt, "lan", "viz", 64, 100));
  const ReloadPlan plan = Gateway::plan_reload(config, gateway.reload_base());
  EXPECT_EQ(plan.reused, before);
  expect_same_as_from_scratch(plan);
  ASSERT_TRUE(gateway.commit_reload(plan).applied);
  // The next reload starts from this one.
  const ReloadPlan again = Gateway::plan_reload(config, gateway.reload_base());
  EXPECT_EQ(again.reused, config.channels.size());
  expect_same_as_from_scratch(again);
}

TEST_F(ReloadPlanTest, AnyOtherChangeIsAdmittedFromScratch) {
  const Config config = base_config();
  ASSERT_TRUE(gateway.start(config).applied);
  const auto base = gateway.reload_base();
  std::vector<Config> changed(5, config);
  changed[0].channels[3].payload = 2;                          // a channel changed
  changed[1].channels.erase(changed[1].channels.begin() + 3);  // a channel removed
  std::swap(changed[2].channels[1], changed[2].channels[2]);   // the order changed
  changed[3].segments[0].can.bitrate = BitRate{250'000};       // a segment changed
  changed[4].channels.push_back(channel("pinned_too", 0x500, ChannelClass::nrt, "bus", "lan", 1, 100));
  changed[4].channels.back().etag = 170;  // a new static etag: reserved from the start
  for (std::size_t i = 0; i < changed.size(); ++i) {
    const ReloadPlan plan = Gateway::plan_reload(changed[i], base);
    EXPECT_EQ(plan.reused, 0u) << "change " << i;
    expect_same_as_from_scratch(plan);
  }
}

TEST_F(ReloadPlanTest, ABindOrUnbindSinceInvalidatesTheBase) {
  const Config config = base_config();
  ASSERT_TRUE(gateway.start(config).applied);
  ASSERT_TRUE(gateway.reload_base());
  ASSERT_TRUE(gateway.unbind("ip3"));
  EXPECT_FALSE(gateway.reload_base());
  // The reload makes the file the truth again, from scratch, and is a base again.
  const ReloadPlan plan = Gateway::plan_reload(config, gateway.reload_base());
  EXPECT_EQ(plan.reused, 0u);
  ASSERT_TRUE(gateway.commit_reload(plan).applied);
  ASSERT_TRUE(gateway.reload_base());
  EXPECT_TRUE(gateway.bind({channel("extra", 0x600, ChannelClass::nrt, "viz", "lan", 8, 100)}).applied);
  EXPECT_FALSE(gateway.reload_base());
}

}  // namespace
}  // namespace cosmic

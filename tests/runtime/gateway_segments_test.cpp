// Segments added to and removed from a running gateway (Gateway::add_segment, remove_segment; the
// run-time replay's segment): the bound channels keep their admission and their etags, a new
// segment carries what a bind then names, and a segment in use stays.
#include <gtest/gtest.h>

#include <chrono>
#include <map>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

class SegmentsTestLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override { lines.emplace_back(message); }
  std::vector<std::string> lines;
};

constexpr const char* kSegmentsConfig = R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: distance, subject: 1, class: srt, period: 10ms, reaction_time: 50ms, payload: 4B, publishers: [body], subscribers: [viz]}
  - {name: bumper, subject: 2, class: nrt, payload: 2B, publishers: [body], subscribers: [viz]}
)";

class GatewaySegmentsTest : public ::testing::Test {
 protected:
  GatewaySegmentsTest()
      : gateway(
            [this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
              auto adapter = std::make_unique<MemoryAdapter>(spec.name);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 0x77) {}

  void SetUp() override {
    const auto parsed = parse_config(kSegmentsConfig, "test.yaml");
    ASSERT_TRUE(parsed.ok()) << parsed.errors.front().to_string();
    ASSERT_TRUE(gateway.start(parsed.config).applied);
  }

  static SegmentSpec lcm_segment(const std::string& name) {
    SegmentSpec spec;
    spec.name = name;
    spec.type = SegmentType::lcm;
    spec.latency_bound = Nanos(1'000'000);
    return spec;
  }

  std::vector<ChannelSpec> channels(const std::string& text) {
    auto result = parse_channels(text, "bind.yaml", gateway.config());
    EXPECT_TRUE(result.ok()) << (result.errors.empty() ? "" : result.errors[0].to_string());
    return result.channels;
  }

  SegmentsTestLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway;
};

TEST_F(GatewaySegmentsTest, AnAddedSegmentKeepsEveryBindingAndItsEtag) {
  const auto etag = gateway.knowledge_base().etag_of("distance");
  ASSERT_TRUE(etag.has_value());
  const auto generation = gateway.generation();
  ASSERT_TRUE(gateway.add_segment(lcm_segment("sim")).ok());
  EXPECT_NE(gateway.generation(), generation);
  EXPECT_NE(gateway.config().find_segment("sim"), nullptr);
  EXPECT_EQ(gateway.knowledge_base().etag_of("distance"), etag);
  EXPECT_EQ(gateway.knowledge_base().bound_channels().size(), 2u);
  ASSERT_EQ(adapters.count("sim"), 1u);
  // The new segment carries a channel once a replacement names it, and events flow from it.
  const auto replaced =
      gateway.replace(channels("- {name: distance, subject: 1, class: srt, period: 10ms, reaction_time: 50ms, payload: "
                               "4B, publishers: [sim], subscribers: [viz]}"));
  ASSERT_TRUE(replaced.applied) << replaced.error;
  const std::size_t before = adapters["viz"]->sent().size();
  ASSERT_TRUE(adapters["sim"]->inject("distance", {1, 2, 3, 4}));
  EXPECT_EQ(adapters["viz"]->wait_sent(before + 1, std::chrono::seconds(5)), before + 1);
}

// Every bound channel's CAN identifier, in report order.
std::vector<std::uint32_t> identifiers_on_the_bus(const KnowledgeBase& kb) {
  std::vector<std::uint32_t> ids;
  for (const ChannelReport& channel : kb.report().channels) {
    for (const HopReport& hop : channel.hops) {
      if (hop.can) ids.push_back(hop.can->can_id);
    }
  }
  return ids;
}

// An unbind keeps the bus's priorities (pinned); adding and removing an unrelated segment must not
// plan the bus afresh, which would move the frames of running CAN channels.
TEST_F(GatewaySegmentsTest, AddingAndRemovingASegmentKeepsTheBusPrioritiesAnUnbindPinned) {
  ASSERT_TRUE(gateway
                  .bind(channels("- {name: c3, subject: 3, class: nrt, payload: 2B, publishers: [body], subscribers: "
                                 "[viz]}\n- {name: c4, subject: 4, class: srt, period: 5ms, reaction_time: 50ms, "
                                 "payload: 2B, publishers: [body], subscribers: [viz]}"))
                  .applied);
  ASSERT_TRUE(gateway.unbind("distance"));
  const auto pinned = identifiers_on_the_bus(gateway.knowledge_base());
  ASSERT_FALSE(pinned.empty());
  ASSERT_TRUE(gateway.add_segment(lcm_segment("sim")).ok());
  EXPECT_EQ(identifiers_on_the_bus(gateway.knowledge_base()), pinned);
  ASSERT_TRUE(gateway.remove_segment("sim").ok());
  EXPECT_EQ(identifiers_on_the_bus(gateway.knowledge_base()), pinned);
}

TEST_F(GatewaySegmentsTest, ATakenNameIsRefusedAndNothingChanges) {
  const auto generation = gateway.generation();
  const auto added = gateway.add_segment(lcm_segment("viz"));
  ASSERT_FALSE(added.ok());
  EXPECT_NE(added.error().text.find("a segment named 'viz' is running"), std::string::npos) << added.error().text;
  EXPECT_EQ(gateway.generation(), generation);
  EXPECT_EQ(gateway.config().segments.size(), 2u);
}

TEST_F(GatewaySegmentsTest, ASegmentStaysWhileABoundChannelUsesIt) {
  ASSERT_TRUE(gateway.add_segment(lcm_segment("sim")).ok());
  ASSERT_TRUE(
      gateway.bind(channels("- {name: probe, subject: 3, class: nrt, publishers: [sim], subscribers: [viz]}")).applied);
  const auto refused = gateway.remove_segment("sim");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().text.find("channel probe still has a hop on segment sim"), std::string::npos);
  EXPECT_NE(gateway.config().find_segment("sim"), nullptr);
  ASSERT_TRUE(gateway.unbind("probe"));
  const auto etag = gateway.knowledge_base().etag_of("distance");
  ASSERT_TRUE(gateway.remove_segment("sim").ok());
  EXPECT_EQ(gateway.config().find_segment("sim"), nullptr);
  EXPECT_EQ(gateway.knowledge_base().etag_of("distance"), etag);
  EXPECT_EQ(gateway.segments().size(), 2u);
  EXPECT_FALSE(gateway.remove_segment("sim").ok());
}

TEST_F(GatewaySegmentsTest, AReloadWithoutTheAddedSegmentRemovesIt) {
  ASSERT_TRUE(gateway.add_segment(lcm_segment("sim")).ok());
  const auto parsed = parse_config(kSegmentsConfig, "test.yaml");
  ASSERT_TRUE(gateway.reload(parsed.config).applied);
  EXPECT_EQ(gateway.config().find_segment("sim"), nullptr);
  EXPECT_EQ(gateway.segments().size(), 2u);
}

}  // namespace
}  // namespace cosmic

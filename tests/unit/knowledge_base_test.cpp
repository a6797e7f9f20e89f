// KnowledgeBase: incremental binding (a newcomer never breaks an admitted HRT channel, a rejected
// channel changes nothing), etag assignment and release, admit_all ordering.
#include "cosmic/knowledge_base.hpp"

#include <gtest/gtest.h>

#include <map>

#include "cosmic/can_wire.hpp"
#include "cosmic/report.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;

// A 125 kbit/s bus (8 B extended frame = 1.28 ms, 1 B = 90 bits = 720 us), a TSN LAN with a
// 100 us bound and a gateway residence bound of 100 us.
KnowledgeBase slow_bus_kb(std::set<std::uint16_t> reserved = {}) {
  return KnowledgeBase(gateway(100us), {can_segment("can", 125'000), dds_segment("lan", 100us)}, std::move(reserved));
}

// HRT, reaction 2.5 ms: alone R = 1.28 ms, e2e = 1.28 + 0.1 + 0.1 = 1.48 ms. Blocked by a 1 B
// frame: R = 0.72 + 1.28 = 2.0 ms, e2e = 2.2 ms: still fine.
ChannelSpec brake() {
  return channel("brake", 0x100, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us));
}
// SRT, reaction 50 ms: lower priority than brake, but its 1.28 ms frame can block brake.
ChannelSpec logger() {
  return channel("logger", 0x200, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(50ms));
}
ChannelSpec small(const std::string& name, std::uint64_t subject) {
  return channel(name, subject, ChannelClass::nrt, {"lan"}, {"can"}, 1, Nanos(100ms));
}

std::string snapshot(const KnowledgeBase& kb) { return to_json(kb.report()).dump(); }

TEST(KnowledgeBase, BindsAndReports) {
  KnowledgeBase kb = slow_bus_kb();
  const BindOutcome out = kb.bind(brake());
  EXPECT_TRUE(out.bound()) << reasons_text(out.report);
  EXPECT_EQ(out.report.verdict, Verdict::bound);
  EXPECT_EQ(find_hop(out.report, "can")->can->response_time, Nanos(1280us));
  EXPECT_EQ(kb.bound_channels().size(), 1u);
  ASSERT_NE(kb.find_bound("brake"), nullptr);
  EXPECT_EQ(kb.etag_of("brake"), 16383);  // handed out downward from 16383
  const AdmissionReport report = kb.report();
  ASSERT_EQ(report.channels.size(), 1u);
  EXPECT_EQ(report.channels[0].name, "brake");
  EXPECT_EQ(report.segments.size(), 2u);
  EXPECT_DOUBLE_EQ(report.segments[0].utilization, 0.128);  // 1.28 ms / 10 ms
  EXPECT_FALSE(report.any_rejected());
}

TEST(KnowledgeBase, NewcomerThatWouldBreakHrtIsRejected) {
  KnowledgeBase kb = slow_bus_kb();
  ASSERT_TRUE(kb.bind(brake()).bound());
  const std::string before = snapshot(kb);
  // The logger alone is fine (R = 1.28 + 1.28 = 2.56 ms <= 50 ms), but its frame blocks brake:
  // R_brake = B + C = 1.28 + 1.28 = 2.56 ms > 2.5 ms.
  const ChannelReport probed = kb.probe(logger());
  EXPECT_EQ(probed.verdict, Verdict::rejected);
  const BindOutcome out = kb.bind(logger());
  EXPECT_FALSE(out.bound());
  EXPECT_EQ(out.report.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(out.report, "would break hrt channel brake: R = 2.56 ms > reaction_time 2.5 ms on can"))
      << reasons_text(out.report);
  EXPECT_EQ(find_hop(out.report, "can")->can->response_time, Nanos(2560us));  // its own R, in the new set
  // Nothing changed: same report, no reservation, no etag taken.
  EXPECT_EQ(snapshot(kb), before);
  EXPECT_EQ(kb.bound_channels().size(), 1u);
  EXPECT_EQ(kb.find_bound("logger"), nullptr);
  EXPECT_FALSE(kb.etag_of("logger").has_value());
  EXPECT_EQ(find_hop(kb.report().channels[0], "can")->can->response_time, Nanos(1280us));
  ASSERT_TRUE(kb.bind(small("next", 0x300)).bound());
  EXPECT_EQ(kb.etag_of("next"), 16382);  // 16382 was never handed to the rejected logger
}

TEST(KnowledgeBase, NewcomerMayDegradeSrtButNotBreakHrt) {
  // Two SRT channels: the second pushes the first over its reaction time; SRT is only warned.
  KnowledgeBase kb = slow_bus_kb();
  auto a = channel("a", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us));
  ASSERT_TRUE(kb.bind(a).bound());
  const BindOutcome out = kb.bind(logger());
  EXPECT_TRUE(out.bound()) << reasons_text(out.report);
  EXPECT_EQ(kb.report().find("a")->verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(*kb.report().find("a"), "R = 2.56 ms > reaction_time 2.5 ms on can"));
}

TEST(KnowledgeBase, RejectedChannelChangesNothing) {
  KnowledgeBase kb = slow_bus_kb();
  ASSERT_TRUE(kb.bind(brake()).bound());
  const std::string before = snapshot(kb);
  const BindOutcome big = kb.bind(channel("big", 0x400, ChannelClass::srt, {"can"}, {"lan"}, 9));  // frame fit
  EXPECT_FALSE(big.bound());
  EXPECT_TRUE(has_reason(big.report, "payload 9 B > frame 8 B on can"));
  EXPECT_FALSE(kb.bind(brake()).bound());  // already bound
  EXPECT_TRUE(has_reason(kb.probe(brake()), "channel brake is already bound"));
  auto same_subject = small("other", brake().subject);
  const BindOutcome dup = kb.bind(same_subject);
  EXPECT_FALSE(dup.bound());
  EXPECT_TRUE(has_reason(dup.report, "subject already carried by bound channel brake"));
  EXPECT_EQ(snapshot(kb), before);
  EXPECT_EQ(kb.bound_channels().size(), 1u);
}

TEST(KnowledgeBase, UnbindFreesEtagAndLoad) {
  KnowledgeBase kb = slow_bus_kb();
  ASSERT_TRUE(kb.bind(brake()).bound());
  auto second = channel("second", 0x500, ChannelClass::nrt, {"can"}, {"lan"}, 1, Nanos(20ms));
  ASSERT_TRUE(kb.bind(second).bound());
  EXPECT_EQ(kb.etag_of("brake"), 16383);
  EXPECT_EQ(kb.etag_of("second"), 16382);
  // 1.28/10 + 0.72/20 = 0.128 + 0.036 = 0.164.
  EXPECT_NEAR(kb.report().segments[0].utilization, 0.164, 1e-12);
  EXPECT_TRUE(kb.unbind("brake"));
  EXPECT_FALSE(kb.unbind("brake"));
  EXPECT_FALSE(kb.unbind("nosuch"));
  EXPECT_FALSE(kb.etag_of("brake").has_value());
  EXPECT_NEAR(kb.report().segments[0].utilization, 0.036, 1e-12);
  EXPECT_EQ(kb.report().channels.size(), 1u);
  // The freed etag is handed out again, highest first.
  ASSERT_TRUE(kb.bind(small("third", 0x600)).bound());
  EXPECT_EQ(kb.etag_of("third"), 16383);
  // The logger that would have broken brake now fits.
  EXPECT_TRUE(kb.bind(logger()).bound());
  EXPECT_EQ(kb.etag_of("logger"), 16381);
}

// Twenty HRT channels share the 16 HRT priority levels of a 125 kbit/s bus (frame C = 1.28 ms,
// periods 1 s, so R = (frames ahead + 2) * C with one blocking frame). Levels are spread as
// rank * 16 / count; channels on one level are ordered by etag, and etags go downward in bind
// order. Bound in the order below, x (rank 6) shares its level with r5 and wins (bound later):
// 5 frames ahead, R = 8.96 ms, e2e 9.16 ms <= 11 ms. Unbinding the last channel (r19) would
// re-spread 19 channels so that x shares a level with y, bound after it, which then wins: 7 frames
// ahead, R = 11.52 ms, e2e 11.72 ms > 11 ms. Unbinding must keep every priority instead.
TEST(KnowledgeBase, UnbindKeepsPrioritiesOfBoundChannels) {
  KnowledgeBase kb = slow_bus_kb();
  auto hrt = [](const std::string& name, std::uint64_t subject, Nanos reaction) {
    return channel(name, subject, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(1s), reaction);
  };
  std::vector<ChannelSpec> order;
  for (std::uint64_t r = 1; r <= 4; ++r) order.push_back(hrt("r" + std::to_string(r), r + 1, Nanos(9500us)));
  order.push_back(hrt("r5", 6, Nanos(11ms)));
  order.push_back(hrt("x", 7, Nanos(11ms)));
  order.push_back(hrt("y", 8, Nanos(30ms)));
  for (std::uint64_t r = 8; r <= 19; ++r) order.push_back(hrt("r" + std::to_string(r), r + 1, Nanos(30ms)));
  order.push_back(hrt("r0", 1, Nanos(9500us)));
  for (const auto& c : order) ASSERT_TRUE(kb.bind(c).bound()) << c.name << ": " << reasons_text(kb.probe(c));
  std::map<std::string, std::uint32_t> ids;
  for (const auto& r : kb.report().channels) ids[r.name] = find_hop(r, "can")->can->can_id;
  EXPECT_EQ(find_hop(*kb.report().find("x"), "can")->can->response_time, Nanos(8960us));

  ASSERT_TRUE(kb.unbind("r19"));
  const AdmissionReport after = kb.report();
  for (const auto& r : after.channels) {
    EXPECT_EQ(find_hop(r, "can")->can->can_id, ids[r.name]) << r.name;
    EXPECT_NE(r.verdict, Verdict::rejected) << r.name << ": " << reasons_text(r);
  }
  EXPECT_EQ(find_hop(*after.find("x"), "can")->can->response_time, Nanos(8960us));

  // A bind elsewhere leaves the bus as it is; the next bind onto the bus plans it afresh, and the
  // fresh plan would break x, so that bind is refused and nothing changes.
  ASSERT_TRUE(kb.bind(channel("ip", 100, ChannelClass::nrt, {"lan"}, {"lan"}, 8, Nanos(1s))).bound());
  EXPECT_EQ(find_hop(*kb.report().find("x"), "can")->can->can_id, ids["x"]);
  const BindOutcome late = kb.bind(small("late", 101));
  EXPECT_FALSE(late.bound());
  EXPECT_TRUE(has_reason(late.report, "would break hrt channel x: R = 11.5 ms > reaction_time 11 ms on can"))
      << reasons_text(late.report);
  EXPECT_EQ(find_hop(*kb.report().find("x"), "can")->can->can_id, ids["x"]);
}

TEST(KnowledgeBase, StaticEtags) {
  KnowledgeBase kb = slow_bus_kb({500, 16383});
  auto fixed = small("fixed", 1);
  fixed.etag = 500;
  ASSERT_TRUE(kb.bind(fixed).bound());
  EXPECT_EQ(kb.etag_of("fixed"), 500);
  const AdmissionReport report = kb.report();
  const CanHopPlan& plan = *find_hop(report.channels[0], "can")->can;
  EXPECT_EQ(plan.etag, 500);
  EXPECT_EQ(plan.can_id & 0x3FFFu, 500u);
  EXPECT_EQ(plan.can_id, encode_can_id(CanIdentifier{0xF0, 1, 500}));
  // A dynamic etag skips the reserved 16383.
  ASSERT_TRUE(kb.bind(small("dynamic", 2)).bound());
  EXPECT_EQ(kb.etag_of("dynamic"), 16382);
  // A second channel asking for etag 500 is rejected.
  auto clash = small("clash", 3);
  clash.etag = 500;
  const BindOutcome out = kb.bind(clash);
  EXPECT_FALSE(out.bound());
  EXPECT_TRUE(has_reason(out.report, "etag 500 is already used by channel fixed")) << reasons_text(out.report);
  // Freed on unbind: now it may be used.
  EXPECT_TRUE(kb.unbind("fixed"));
  EXPECT_TRUE(kb.bind(clash).bound());
  EXPECT_EQ(kb.etag_of("clash"), 500);
}

TEST(KnowledgeBase, IpOnlyChannelsTakeNoEtag) {
  KnowledgeBase kb(gateway(), {dds_segment("lan"), lcm_segment("viz")});
  ASSERT_TRUE(kb.bind(channel("c", 1, ChannelClass::nrt, {"lan"}, {"viz"}, 8, Nanos(10ms))).bound());
  EXPECT_FALSE(kb.etag_of("c").has_value());
}

TEST(KnowledgeBase, EtagsRunOut) {
  // 101..16383 are 16283 etags; reserve all but one.
  std::set<std::uint16_t> reserved;
  for (std::uint16_t e = 102; e <= kMaxEtag; ++e) reserved.insert(e);
  KnowledgeBase kb = slow_bus_kb(reserved);
  ASSERT_TRUE(kb.bind(small("last", 1)).bound());
  EXPECT_EQ(kb.etag_of("last"), 101);
  const BindOutcome out = kb.bind(small("none", 2));
  EXPECT_FALSE(out.bound());
  EXPECT_TRUE(has_reason(out.report, "no free etag left")) << reasons_text(out.report);
}

TEST(KnowledgeBase, HealthDegradesReport) {
  KnowledgeBase kb = slow_bus_kb();
  ASSERT_TRUE(kb.bind(brake()).bound());
  kb.set_health("lan", SegmentHealth::down, "link lost");
  const AdmissionReport report = kb.report();
  const ChannelReport& r = *report.find("brake");
  EXPECT_EQ(r.verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(r, "segment lan is down: link lost"));
  kb.set_health("lan", SegmentHealth::up, "");
  EXPECT_EQ(kb.report().find("brake")->verdict, Verdict::bound);
}

TEST(AdmitAll, RejectedChannelsComeAfterBoundOnes) {
  Config config;
  config.gateway = gateway(100us);
  config.segments = {can_segment("can", 125'000), dds_segment("lan", 100us)};
  auto big = channel("big", 0x400, ChannelClass::srt, {"can"}, {"lan"}, 9);
  auto late = small("late", 0x700);
  late.etag = 16383;  // static: reserved from the start, so "brake" gets 16382
  config.channels = {big, brake(), logger(), late};
  const AdmissionReport report = admit_all(config);
  ASSERT_EQ(report.channels.size(), 4u);
  EXPECT_EQ(report.channels[0].name, "brake");
  EXPECT_EQ(report.channels[0].verdict, Verdict::bound);
  EXPECT_EQ(report.channels[1].name, "late");
  EXPECT_EQ(report.channels[1].verdict, Verdict::bound);
  EXPECT_EQ(report.channels[2].name, "big");
  EXPECT_EQ(report.channels[2].verdict, Verdict::rejected);
  EXPECT_EQ(report.channels[3].name, "logger");
  EXPECT_EQ(report.channels[3].verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(report.channels[3], "would break hrt channel brake")) << reasons_text(report.channels[3]);
  EXPECT_TRUE(report.any_rejected());
  // brake got the highest free etag; late kept its static one.
  EXPECT_EQ(find_hop(report.channels[0], "can")->can->etag, 16382);
  EXPECT_EQ(find_hop(report.channels[1], "can")->can->etag, 16383);
  // Loads are those of the bound set: brake 1.28/10 + late 1 B frame (90 bits * 8 us = 720 us)
  // every 100 ms = 0.128 + 0.0072.
  EXPECT_NEAR(report.segments[0].utilization, 0.1352, 1e-12);
}

}  // namespace
}  // namespace cosmic

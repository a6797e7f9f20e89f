// evaluate(): every check of DESIGN.md §4 with hand-computed figures, and the verdict rules
// (HRT: any failure rejects; SRT: degraded, except frame fit which rejects; NRT: may fragment).
#include "cosmic/admission.hpp"

#include <gtest/gtest.h>

#include "cosmic/can_wire.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;

Evaluation run(std::vector<SegmentSpec> segments, std::vector<ChannelSpec> channels, EtagMap etags = {},
               GatewaySpec gw = gateway()) {
  return evaluate(gw, segments, channels, etags);
}

const ChannelReport& only(const Evaluation& e) {
  EXPECT_EQ(e.channels.size(), 1u);
  return e.channels.front();
}

// ---------------------------------------------------------------- frame fit

TEST(FrameFit, HrtAndSrtMustFitOneClassicFrame) {
  for (const ChannelClass cls : {ChannelClass::hrt, ChannelClass::srt}) {
    const auto e = run({can_segment("can"), dds_segment("lan")}, {channel("big", 1, cls, {"can"}, {"lan"}, 9)});
    const ChannelReport& r = only(e);
    EXPECT_EQ(r.verdict, Verdict::rejected) << to_string(cls);  // frame fit rejects SRT too
    const Check* fit = find_check(*find_hop(r, "can"), "frame_fit");
    ASSERT_NE(fit, nullptr);
    EXPECT_FALSE(fit->ok);
    EXPECT_EQ(fit->value, 9.0);
    EXPECT_EQ(fit->limit, 8.0);
    EXPECT_EQ(fit->unit, "B");
    EXPECT_TRUE(has_reason(r, "payload 9 B > frame 8 B on can")) << reasons_text(r);
  }
  const auto ok =
      run({can_segment("can"), dds_segment("lan")}, {channel("small", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8)});
  EXPECT_EQ(only(ok).verdict, Verdict::bound) << reasons_text(only(ok));
  EXPECT_TRUE(find_check(*find_hop(only(ok), "can"), "frame_fit")->ok);
}

TEST(FrameFit, FdCarries64PaddedBytes) {
  SegmentSpec fd = can_segment("fd");
  fd.can.fd = true;
  fd.can.data_bitrate = BitRate{2'000'000};
  auto e = run({fd, dds_segment("lan")}, {channel("c", 1, ChannelClass::srt, {"fd"}, {"lan"}, 10)});
  const HopReport* hop = find_hop(only(e), "fd");
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
  EXPECT_EQ(hop->can->frame_bytes, 12u);  // 10 B travel in a 12-byte FD frame
  EXPECT_EQ(find_check(*hop, "frame_fit")->limit, 64.0);
  // 64 B extended at 500k/2M: 451.5 us (see can_timing_test).
  e = run({fd, dds_segment("lan")}, {channel("c", 1, ChannelClass::hrt, {"fd"}, {"lan"}, 64)});
  EXPECT_EQ(find_hop(only(e), "fd")->can->transmission, Nanos(451'500));
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
  e = run({fd, dds_segment("lan")}, {channel("c", 1, ChannelClass::hrt, {"fd"}, {"lan"}, 65)});
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(only(e), "payload 65 B > frame 64 B on fd")) << reasons_text(only(e));
}

TEST(FrameFit, NrtFragmentsOnCan) {
  // 256 B in 8-byte frames with a 2-byte header: ceil(256 / 6) = 43 frames of 160 bits (320 us at
  // 500 kbit/s) every 100 ms: load 43 * 0.32 / 100 = 0.1376.
  auto c = channel("diag", 1, ChannelClass::nrt, {"can"}, {"lan"}, 256, Nanos(100ms));
  const auto e = run({can_segment("can"), dds_segment("lan")}, {c});
  const ChannelReport& r = only(e);
  EXPECT_EQ(r.verdict, Verdict::bound) << reasons_text(r);
  const HopReport* hop = find_hop(r, "can");
  EXPECT_EQ(hop->can->frames_per_event, 43u);
  EXPECT_EQ(hop->can->frame_bytes, 8u);
  EXPECT_EQ(hop->can->transmission, Nanos(320us));
  EXPECT_TRUE(find_check(*hop, "frame_fit")->ok);
  EXPECT_EQ(find_check(*hop, "frame_fit")->limit, 2048.0 * 6.0);  // kMaxFragments fragments of 6 B
  EXPECT_NEAR(e.segments[0].utilization, 0.1376, 1e-9);
  EXPECT_EQ(find_check(*hop, "response_time"), nullptr);  // NRT: no bound asked
  // Beyond 2048 fragments even NRT is rejected.
  c.payload = 2048 * 6 + 1;
  EXPECT_EQ(only(run({can_segment("can"), dds_segment("lan")}, {c})).verdict, Verdict::rejected);
}

TEST(FrameFit, IpMessageSize) {
  SegmentSpec lan = dds_segment("lan");
  lan.max_message_size = 1096;  // 1000 B payload + 96 B envelope and headers
  auto e = run({lan, dds_segment("lan2")}, {channel("c", 1, ChannelClass::srt, {"lan"}, {"lan2"}, 1001)});
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(only(e), "payload 1001 B > message 1000 B on lan")) << reasons_text(only(e));
  e = run({lan, dds_segment("lan2")}, {channel("c", 1, ChannelClass::srt, {"lan"}, {"lan2"}, 1000)});
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
  // NRT events on IP segments may be up to 1 MiB whatever the message size.
  e = run({lan, dds_segment("lan2")}, {channel("c", 1, ChannelClass::nrt, {"lan"}, {"lan2"}, 1 << 20)});
  EXPECT_TRUE(find_check(*find_hop(only(e), "lan"), "frame_fit")->ok);
}

// ---------------------------------------------------------------- bandwidth

TEST(Bandwidth, CanUtilizationAgainstMaxUtilization) {
  // 125 kbit/s: 8 B extended = 160 * 8 us = 1.28 ms; every 1.6 ms: U = 0.8 > 0.7.
  // R = 1.28 ms alone; e2e = 1.28 + 0.5 + 1 = 2.78 ms <= 10 ms: only utilization fails.
  auto c = channel("c", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(1600us), Nanos(10ms));
  auto e = run({can_segment("can", 125'000), dds_segment("lan")}, {c});
  EXPECT_DOUBLE_EQ(e.segments[0].utilization, 0.8);
  EXPECT_DOUBLE_EQ(e.segments[0].max_utilization, 0.7);
  EXPECT_EQ(e.segments[0].type, SegmentType::can);
  const ChannelReport& r = only(e);
  EXPECT_EQ(r.verdict, Verdict::degraded);
  ASSERT_EQ(r.reasons.size(), 1u) << reasons_text(r);
  EXPECT_EQ(r.reasons[0], "utilization 80.0% > max_utilization 70.0% on can");
  const Check* u = find_check(*find_hop(r, "can"), "utilization");
  EXPECT_FALSE(u->ok);
  EXPECT_EQ(u->unit, "ratio");
  // The same load for an HRT channel is a rejection.
  c.cls = ChannelClass::hrt;
  EXPECT_EQ(only(run({can_segment("can", 125'000), dds_segment("lan", 1ms)}, {c})).verdict, Verdict::rejected);
  // With a 90 % limit it fits.
  c.cls = ChannelClass::srt;
  EXPECT_EQ(only(run({can_segment("can", 125'000, 0.9), dds_segment("lan")}, {c})).verdict, Verdict::bound);
}

TEST(Bandwidth, LoadsAddUpOverChannels) {
  // 500 kbit/s, 8 B: 320 us. Every 10 ms and every 5 ms: 0.032 + 0.064 = 0.096.
  const auto e = run({can_segment("can"), dds_segment("lan")},
                     {channel("a", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(10ms)),
                      channel("b", 2, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(5ms), Nanos(10ms))});
  EXPECT_NEAR(e.segments[0].utilization, 0.096, 1e-12);
  // DDS: (8 + 96) * 8 = 832 bits per event on 100 Mbit/s: 832/0.01/1e8 + 832/0.005/1e8.
  EXPECT_NEAR(e.segments[1].utilization, 832.0 / 0.01 / 1e8 + 832.0 / 0.005 / 1e8, 1e-12);
}

TEST(Bandwidth, IpUtilization) {
  // 1000 B + 96 B every 10 ms over a 1 Mbit/s link: 8768 bits / 0.01 s = 876.8 kbit/s: 87.68 %.
  SegmentSpec slow = dds_segment("slow");
  slow.bandwidth = BitRate{1'000'000};
  const auto e = run({slow, dds_segment("lan")},
                     {channel("c", 1, ChannelClass::srt, {"slow"}, {"lan"}, 1000, Nanos(10ms), Nanos(10ms))});
  EXPECT_NEAR(e.segments[0].utilization, 0.8768, 1e-12);
  EXPECT_EQ(only(e).verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(only(e), "utilization 87.7% > max_utilization 70.0% on slow")) << reasons_text(only(e));
}

TEST(Bandwidth, UnratedChannelReservesNothing) {
  const auto e = run({can_segment("can"), dds_segment("lan")},
                     {channel("c", 1, ChannelClass::nrt, {"can"}, {"lan"}, 8, std::nullopt)});
  EXPECT_EQ(e.segments[0].utilization, 0.0);
  EXPECT_EQ(find_check(*find_hop(only(e), "can"), "utilization"), nullptr);
  EXPECT_EQ(only(e).verdict, Verdict::bound);
}

// ---------------------------------------------------------------- CAN response time

TEST(ResponseTimeCheck, BlockingPushesOverReactionTime) {
  // 125 kbit/s, two 8 B channels (1.28 ms each). "tight" has the shorter reaction time, so the
  // higher priority, but a frame of "loose" may have just started: R = 1.28 + 1.28 = 2.56 ms >
  // 2.5 ms. "loose": w = ceil(0.008/10) * 1.28 = 1.28, R = 2.56 ms <= 10 ms.
  SegmentSpec lan = dds_segment("lan", 100us);
  const auto e = run({can_segment("can", 125'000), lan},
                     {channel("loose", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(10ms)),
                      channel("tight", 2, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us))});
  const ChannelReport& tight = e.channels[1];
  const HopReport* hop = find_hop(tight, "can");
  EXPECT_EQ(hop->can->priority, 0);
  EXPECT_EQ(hop->can->response_time, Nanos(2'560'000));
  EXPECT_EQ(hop->latency, Nanos(2'560'000));
  const Check* rt = find_check(*hop, "response_time");
  EXPECT_FALSE(rt->ok);
  EXPECT_DOUBLE_EQ(rt->value, 0.00256);
  EXPECT_DOUBLE_EQ(rt->limit, 0.0025);
  EXPECT_EQ(rt->unit, "s");
  EXPECT_EQ(rt->relation, "<=");
  EXPECT_EQ(tight.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(tight, "R = 2.56 ms > reaction_time 2.5 ms on can")) << reasons_text(tight);
  const ChannelReport& loose = e.channels[0];
  EXPECT_EQ(find_hop(loose, "can")->can->response_time, Nanos(2'560'000));
  EXPECT_EQ(loose.verdict, Verdict::bound) << reasons_text(loose);
  // The same miss for an SRT channel only degrades it.
  const auto s = run({can_segment("can", 125'000), lan},
                     {channel("loose", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(10ms)),
                      channel("tight", 2, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(2500us))});
  EXPECT_EQ(s.channels[1].verdict, Verdict::degraded);
}

TEST(ResponseTimeCheck, FaultHypothesisTerm) {
  // 125 kbit/s, one 8 B frame (1.28 ms) every 10 ms; one error per 10 ms costs 31 * 8 us +
  // 1.28 ms = 1.528 ms: R = 1.28 + 1.528 = 2.808 ms.
  SegmentSpec bus = can_segment("can", 125'000);
  bus.can.errors = CanFaultHypothesis{1, Nanos(10ms)};
  auto c = channel("c", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(10ms));
  auto e = run({bus, dds_segment("lan", 100us)}, {c});
  EXPECT_EQ(find_hop(only(e), "can")->can->response_time, Nanos(2'808'000));
  // max_per_window 0: no fault term.
  bus.can.errors = CanFaultHypothesis{0, Nanos(10ms)};
  e = run({bus, dds_segment("lan", 100us)}, {c});
  EXPECT_EQ(find_hop(only(e), "can")->can->response_time, Nanos(1'280'000));
}

TEST(ResponseTimeCheck, OverloadIsUnbounded) {
  // Two 8 B channels every 2 ms on 125 kbit/s: 2 * 1.28 / 2 = 128 %.
  const auto e = run({can_segment("can", 125'000), dds_segment("lan")},
                     {channel("a", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(2ms), Nanos(10ms)),
                      channel("b", 2, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(2ms), Nanos(10ms))});
  const ChannelReport& b = e.channels[1];
  EXPECT_FALSE(find_hop(b, "can")->can->response_time.has_value());
  EXPECT_FALSE(find_hop(b, "can")->latency.has_value());
  EXPECT_FALSE(b.end_to_end.latency.has_value());
  EXPECT_FALSE(b.end_to_end.latency_ok);
  EXPECT_EQ(b.verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(b, "R = unbounded > reaction_time 10 ms on can")) << reasons_text(b);
}

// ---------------------------------------------------------------- priorities and identifiers

TEST(Priorities, DeadlineMonotonicInsideBands) {
  const auto e =
      run({can_segment("can"), dds_segment("lan")},
          {channel("s20", 1, ChannelClass::srt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(20ms)),
           channel("s5", 2, ChannelClass::srt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(5ms)),
           channel("n", 3, ChannelClass::nrt, {"can"}, {"lan"}, 1, Nanos(50ms)),
           channel("s10", 4, ChannelClass::srt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(10ms)),
           channel("h9", 5, ChannelClass::hrt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(9ms)),
           channel("h3", 6, ChannelClass::hrt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(3ms)),
           channel("n_fast", 7, ChannelClass::nrt, {"can"}, {"lan"}, 1, Nanos(20ms))},
          {{"s20", 16383}, {"s5", 16382}, {"n", 16381}, {"s10", 16380}, {"h9", 16379}, {"h3", 16378}, {"n_fast", 200}});
  auto prio = [&](std::size_t i) { return e.channels[i].hops[0].can->priority; };
  EXPECT_EQ(prio(5), 0x00);  // h3
  EXPECT_EQ(prio(4), 0x01);  // h9
  EXPECT_EQ(prio(1), 0x10);  // s5
  EXPECT_EQ(prio(3), 0x11);  // s10
  EXPECT_EQ(prio(0), 0x12);  // s20
  EXPECT_EQ(prio(6), 0xF0);  // NRT without reaction_time: ordered by period, 20 ms first
  EXPECT_EQ(prio(2), 0xF1);
  // can_id = priority << 21 | node << 14 | etag.
  EXPECT_EQ(e.channels[0].hops[0].can->can_id, (0x12u << 21) | (1u << 14) | 16383u);
  EXPECT_EQ(e.channels[0].hops[0].can->etag, 16383);
  EXPECT_EQ(e.channels[6].hops[0].can->can_id, (0xF0u << 21) | (1u << 14) | 200u);
  // Shorter reaction time -> smaller identifier -> wins arbitration.
  EXPECT_LT(e.channels[1].hops[0].can->can_id, e.channels[3].hops[0].can->can_id);
  EXPECT_LT(e.channels[4].hops[0].can->can_id, e.channels[1].hops[0].can->can_id);
}

TEST(Priorities, EqualDeadlinesOrderedBySubject) {
  const auto e = run({can_segment("can"), dds_segment("lan")},
                     {channel("b", 0x20, ChannelClass::srt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(5ms)),
                      channel("a", 0x10, ChannelClass::srt, {"can"}, {"lan"}, 1, Nanos(50ms), Nanos(5ms))});
  EXPECT_EQ(e.channels[1].hops[0].can->priority, 0x10);
  EXPECT_EQ(e.channels[0].hops[0].can->priority, 0x11);
}

TEST(Priorities, GatewayNodeInIdentifier) {
  const auto e = run({can_segment("can"), dds_segment("lan")},
                     {channel("c", 1, ChannelClass::hrt, {"can"}, {"lan"}, 1)}, {{"c", 4242}}, gateway(500us, 99));
  const CanIdentifier id = decode_can_id(e.channels[0].hops[0].can->can_id);
  EXPECT_EQ(id, (CanIdentifier{0, 99, 4242}));
}

// ---------------------------------------------------------------- latency budget and validity

TEST(LatencyBudget, PublisherPlusResidencePlusSubscriber) {
  // 2 ms + 0.5 ms + 3 ms = 5.5 ms > 5 ms; each hop alone is within 5 ms.
  auto c = channel("c", 1, ChannelClass::srt, {"p"}, {"s"}, 8, Nanos(10ms), Nanos(5ms));
  auto e = run({dds_segment("p", 2ms), dds_segment("s", 3ms)}, {c});
  const ChannelReport& r = only(e);
  EXPECT_EQ(r.end_to_end.latency, Nanos(5500us));
  EXPECT_EQ(r.end_to_end.reaction_time, Nanos(5ms));
  EXPECT_FALSE(r.end_to_end.latency_ok);
  EXPECT_TRUE(r.end_to_end.validity_ok);
  EXPECT_EQ(r.verdict, Verdict::degraded);
  ASSERT_EQ(r.reasons.size(), 1u) << reasons_text(r);
  EXPECT_EQ(r.reasons[0], "end-to-end latency 5.5 ms > reaction_time 5 ms");
  EXPECT_TRUE(find_check(*find_hop(r, "p"), "latency")->ok);
  // HRT: rejected. A shorter residence bound makes it fit: 2 + 0.1 + 3 = 5.1 ... still over;
  // 2 + 0.1 + 2.5 = 4.6 fits.
  c.cls = ChannelClass::hrt;
  EXPECT_EQ(only(run({dds_segment("p", 2ms), dds_segment("s", 3ms)}, {c})).verdict, Verdict::rejected);
  e = run({dds_segment("p", 2ms), dds_segment("s", 2500us)}, {c}, {}, gateway(100us));
  EXPECT_EQ(only(e).end_to_end.latency, Nanos(4600us));
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
}

TEST(LatencyBudget, WorstPairOfSeveralHops) {
  // Worst publisher 3 ms, worst subscriber 4 ms: 3 + 0.5 + 4 = 7.5 ms.
  const auto e = run({dds_segment("p1", 1ms), dds_segment("p2", 3ms), dds_segment("s1", 4ms), dds_segment("s2", 2ms)},
                     {channel("c", 1, ChannelClass::srt, {"p1", "p2"}, {"s1", "s2"}, 8, Nanos(10ms), Nanos(20ms))});
  EXPECT_EQ(only(e).end_to_end.latency, Nanos(7500us));
}

TEST(LatencyBudget, IpHopLatencyAgainstReactionTime) {
  // A 6 ms network bound alone exceeds a 5 ms reaction time.
  const auto e = run({dds_segment("p", 6ms), dds_segment("s", 1ms)},
                     {channel("c", 1, ChannelClass::srt, {"p"}, {"s"}, 8, Nanos(10ms), Nanos(5ms))});
  const Check* lat = find_check(*find_hop(only(e), "p"), "latency");
  ASSERT_NE(lat, nullptr);
  EXPECT_FALSE(lat->ok);
  EXPECT_TRUE(has_reason(only(e), "latency_bound 6 ms > reaction_time 5 ms on p")) << reasons_text(only(e));
}

TEST(LatencyBudget, CanPublisherToIp) {
  // 500 kbit/s, 8 B alone: R = 320 us; e2e = 0.32 + 0.5 + 1 = 1.82 ms.
  const auto e = run({can_segment("can"), dds_segment("lan", 1ms)},
                     {channel("c", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(5ms))});
  EXPECT_EQ(find_hop(only(e), "can")->can->response_time, Nanos(320us));
  EXPECT_EQ(find_hop(only(e), "can")->can->jitter, Nanos(0));
  EXPECT_EQ(only(e).end_to_end.latency, Nanos(1820us));
}

TEST(LatencyBudget, CanSubscriberJitterCountedOnce) {
  // DDS (1 ms) -> gateway (0.5 ms) -> CAN 500 kbit/s: the CAN frame is released up to 1.5 ms
  // after the event: J = 1.5 ms, R = J + w + C = 1.5 + 0 + 0.32 = 1.82 ms, measured from the
  // event. End to end: 1 + 0.5 + (1.82 - 1.5) = 1.82 ms, not 1 + 0.5 + 1.82 = 3.32 ms.
  const auto e = run({can_segment("can"), dds_segment("lan", 1ms)},
                     {channel("c", 1, ChannelClass::hrt, {"lan"}, {"can"}, 8, Nanos(10ms), Nanos(2ms))});
  const HopReport* hop = find_hop(only(e), "can");
  EXPECT_EQ(hop->role, HopRole::subscriber);
  EXPECT_EQ(hop->can->jitter, Nanos(1500us));
  EXPECT_EQ(hop->can->response_time, Nanos(1820us));
  EXPECT_EQ(only(e).end_to_end.latency, Nanos(1820us));
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
}

TEST(Validity, EndToEndMustStayBelowTempValidity) {
  // e2e = 0.32 + 0.5 + 1 = 1.82 ms (see above).
  auto c = channel("c", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(5ms));
  c.temp_validity = Nanos(1500us);
  auto e = run({can_segment("can"), dds_segment("lan", 1ms)}, {c});
  EXPECT_FALSE(only(e).end_to_end.validity_ok);
  EXPECT_TRUE(only(e).end_to_end.latency_ok);
  EXPECT_EQ(only(e).end_to_end.temp_validity, Nanos(1500us));
  EXPECT_EQ(only(e).verdict, Verdict::degraded);
  ASSERT_EQ(only(e).reasons.size(), 1u) << reasons_text(only(e));
  EXPECT_EQ(only(e).reasons[0], "end-to-end latency 1.82 ms >= temp_validity 1.5 ms: events would arrive stale");
  // Equal is stale too (strictly below is required) ...
  c.temp_validity = Nanos(1820us);
  EXPECT_FALSE(only(run({can_segment("can"), dds_segment("lan", 1ms)}, {c})).end_to_end.validity_ok);
  // ... 10 us more is fine.
  c.temp_validity = Nanos(1830us);
  EXPECT_EQ(only(run({can_segment("can"), dds_segment("lan", 1ms)}, {c})).verdict, Verdict::bound);
  // HRT: rejected.
  c.temp_validity = Nanos(1500us);
  c.cls = ChannelClass::hrt;
  EXPECT_EQ(only(run({can_segment("can"), dds_segment("lan", 1ms)}, {c})).verdict, Verdict::rejected);
}

// ---------------------------------------------------------------- an FMU's communication step

// An FMU publishes once per step (docs/fmu.md, "Timing and admission"): checked on its publisher hop.
TEST(FmuStep, LongerThanTempValidityDegradesTheChannel) {
  auto c = channel("speed", 1, ChannelClass::srt, {"lan"}, {"viz"}, 8, Nanos(10ms), Nanos(20ms));
  c.temp_validity = Nanos(15ms);
  c.fmu_publishers = {{"speed_fmu", "lan", Nanos(20ms)}};
  auto e = run({dds_segment("lan"), lcm_segment("viz")}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::degraded);
  ASSERT_EQ(only(e).reasons.size(), 1u) << reasons_text(only(e));
  EXPECT_EQ(only(e).reasons[0],
            "fmu speed_fmu publishes every 20 ms (its step), longer than temp_validity 15 ms: between two steps "
            "subscribers hold a value older than its validity");
  const Check* validity = find_check(*find_hop(only(e), "lan"), "fmu_validity");
  ASSERT_NE(validity, nullptr);
  EXPECT_FALSE(validity->ok);
  EXPECT_DOUBLE_EQ(validity->value, 0.020);
  EXPECT_DOUBLE_EQ(validity->limit, 0.015);
  EXPECT_EQ(validity->relation, "<=");
  EXPECT_TRUE(find_check(*find_hop(only(e), "lan"), "fmu_rate")->ok);         // 20 ms >= the period 10 ms
  EXPECT_EQ(find_check(*find_hop(only(e), "viz"), "fmu_validity"), nullptr);  // the subscriber hop: no FMU
  // A step longer than the period but within the validity (equal included) is fine.
  c.fmu_publishers[0].step = Nanos(15ms);
  e = run({dds_segment("lan"), lcm_segment("viz")}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
  EXPECT_TRUE(find_check(*find_hop(only(e), "lan"), "fmu_validity")->ok);
  // HRT: rejected, as for every failing criterion.
  c.fmu_publishers[0].step = Nanos(20ms);
  c.cls = ChannelClass::hrt;
  c.subscribers = {"lan2"};
  e = run({dds_segment("lan"), dds_segment("lan2")}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::rejected) << reasons_text(only(e));
  EXPECT_TRUE(has_reason(only(e), "fmu speed_fmu publishes every 20 ms (its step), longer than temp_validity"));
}

TEST(FmuStep, ShorterThanThePeriodRejects) {
  // A bind at run time (the configuration refuses such a step at load): rate policing would drop
  // every event beyond the period's.
  auto c = channel("speed", 1, ChannelClass::nrt, {"lan"}, {"viz"}, 8, Nanos(10ms), std::nullopt);
  c.fmu_publishers = {{"speed_fmu", "lan", Nanos(5ms)}};
  const auto e = run({dds_segment("lan"), lcm_segment("viz")}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(only(e),
                         "fmu speed_fmu publishes every 5 ms (its step), faster than the period 10 ms: rate policing "
                         "would drop its events"))
      << reasons_text(only(e));
  const Check* rate = find_check(*find_hop(only(e), "lan"), "fmu_rate");
  ASSERT_NE(rate, nullptr);
  EXPECT_DOUBLE_EQ(rate->value, 0.005);
  EXPECT_DOUBLE_EQ(rate->limit, 0.010);
  EXPECT_EQ(find_check(*find_hop(only(e), "lan"), "fmu_validity"), nullptr);  // no temp_validity: nothing to hold
  // An FMU on a segment the channel is not published from adds nothing.
  c.fmu_publishers[0].segment = "viz";
  EXPECT_EQ(only(run({dds_segment("lan"), lcm_segment("viz")}, {c})).verdict, Verdict::bound);
}

// ---------------------------------------------------------------- omission and real-time

TEST(Omission, SegmentsWithoutRetransmission) {
  auto c = channel("c", 1, ChannelClass::srt, {"lan"}, {"viz"}, 8, Nanos(10ms), Nanos(20ms));
  c.omission_degree = 0;
  auto e = run({dds_segment("lan"), lcm_segment("viz")}, {c});
  const Check* om = find_check(*find_hop(only(e), "viz"), "omission");
  EXPECT_FALSE(om->ok);
  EXPECT_EQ(om->value, 0.0);
  EXPECT_EQ(om->limit, 1.0);
  EXPECT_EQ(om->unit, "events");
  EXPECT_TRUE(find_check(*find_hop(only(e), "lan"), "omission")->ok);  // reliable DDS retransmits
  EXPECT_EQ(only(e).verdict, Verdict::degraded);
  EXPECT_TRUE(has_reason(only(e), "omission_degree 0 < 1 on viz, which does not retransmit")) << reasons_text(only(e));
  // Tolerating one loss is fine on LCM.
  c.omission_degree = 1;
  EXPECT_EQ(only(run({dds_segment("lan"), lcm_segment("viz")}, {c})).verdict, Verdict::bound);
  // Best-effort DDS does not retransmit either: HRT with omission 0 is rejected there.
  c.omission_degree = 0;
  c.cls = ChannelClass::hrt;
  c.subscribers = {"be"};
  e = run({dds_segment("lan"), dds_segment("be", 1ms, true, Reliability::best_effort)}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(only(e), "omission_degree 0 < 1 on be")) << reasons_text(only(e));
  // CAN retransmits within the fault hypothesis.
  c.subscribers = {"can"};
  e = run({dds_segment("lan"), can_segment("can")}, {c});
  EXPECT_TRUE(find_check(*find_hop(only(e), "can"), "omission")->ok);
  EXPECT_EQ(only(e).verdict, Verdict::bound) << reasons_text(only(e));
}

TEST(Realtime, HrtOverNonRealtimeNetwork) {
  auto c = channel("c", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(20ms));
  auto e = run({can_segment("can"), dds_segment("lan", 1ms, false)}, {c});
  const Check* rt = find_check(*find_hop(only(e), "lan"), "realtime");
  ASSERT_NE(rt, nullptr);
  EXPECT_FALSE(rt->ok);
  EXPECT_TRUE(find_check(*find_hop(only(e), "can"), "realtime")->ok);  // CAN is real-time capable
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  ASSERT_EQ(only(e).reasons.size(), 1u) << reasons_text(only(e));
  EXPECT_EQ(only(e).reasons[0], "hrt on lan, which declares no real-time guarantee (realtime: false)");
  // A network that declares a bound (TSN) is fine.
  EXPECT_EQ(only(run({can_segment("can"), dds_segment("lan", 1ms, true)}, {c})).verdict, Verdict::bound);
  // SRT is not held to it.
  c.cls = ChannelClass::srt;
  e = run({can_segment("can"), dds_segment("lan", 1ms, false)}, {c});
  EXPECT_EQ(find_check(*find_hop(only(e), "lan"), "realtime"), nullptr);
  EXPECT_EQ(only(e).verdict, Verdict::bound);
  // LCM (plain UDP multicast) for HRT: rejected.
  c.cls = ChannelClass::hrt;
  c.omission_degree = 1;
  c.subscribers = {"viz"};
  e = run({can_segment("can"), lcm_segment("viz", 1ms)}, {c});
  EXPECT_EQ(only(e).verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(only(e), "hrt on viz")) << reasons_text(only(e));
}

// ---------------------------------------------------------------- verdict rules

TEST(Verdicts, NrtIsNeverHeldToTimeBounds) {
  // NRT on an overloaded 125 kbit/s bus: no response-time or latency check, only load.
  auto c = channel("n", 1, ChannelClass::nrt, {"can"}, {"viz"}, 8, Nanos(1ms));
  const auto e = run({can_segment("can", 125'000), lcm_segment("viz")}, {c});
  const ChannelReport& r = only(e);
  EXPECT_FALSE(r.end_to_end.latency.has_value());  // 1.28 ms every 1 ms: unbounded
  EXPECT_TRUE(r.end_to_end.latency_ok);
  EXPECT_EQ(find_check(*find_hop(r, "can"), "response_time"), nullptr);
  EXPECT_EQ(r.verdict, Verdict::degraded);  // the utilization check still warns
  EXPECT_TRUE(has_reason(r, "utilization 128.0% > max_utilization 70.0% on can")) << reasons_text(r);
}

TEST(Verdicts, SeveralFailuresAllReported) {
  // HRT with omission 0 over best-effort, non-real-time DDS whose bound exceeds reaction_time.
  auto c = channel("c", 1, ChannelClass::hrt, {"can"}, {"be"}, 8, Nanos(10ms), Nanos(5ms));
  c.omission_degree = 0;
  const auto e = run({can_segment("can"), dds_segment("be", 6ms, false, Reliability::best_effort)}, {c});
  const ChannelReport& r = only(e);
  EXPECT_EQ(r.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(r, "latency_bound 6 ms > reaction_time 5 ms on be")) << reasons_text(r);
  EXPECT_TRUE(has_reason(r, "omission_degree 0 < 1 on be")) << reasons_text(r);
  EXPECT_TRUE(has_reason(r, "hrt on be")) << reasons_text(r);
  EXPECT_TRUE(has_reason(r, "end-to-end latency")) << reasons_text(r);
}

TEST(Verdicts, HopsInDeclarationOrder) {
  const auto e = run({can_segment("can"), dds_segment("lan"), lcm_segment("viz")},
                     {channel("c", 1, ChannelClass::nrt, {"lan"}, {"viz", "can"}, 4, Nanos(10ms))});
  const ChannelReport& r = only(e);
  ASSERT_EQ(r.hops.size(), 3u);
  EXPECT_EQ(r.hops[0].segment, "lan");
  EXPECT_EQ(r.hops[0].role, HopRole::publisher);
  EXPECT_FALSE(r.hops[0].can.has_value());
  EXPECT_EQ(r.hops[1].segment, "viz");
  EXPECT_EQ(r.hops[2].segment, "can");
  EXPECT_EQ(r.hops[2].role, HopRole::subscriber);
  EXPECT_TRUE(r.hops[2].can.has_value());
  EXPECT_EQ(std::string(to_string(Verdict::degraded)), "degraded");
  EXPECT_EQ(std::string(to_string(HopRole::subscriber)), "subscriber");
}

// ---------------------------------------------------------------- FAMOUSO profile

SegmentSpec famouso_segment(const std::string& name, std::uint64_t bitrate = 500'000) {
  SegmentSpec s = can_segment(name, bitrate);
  s.can.profile = CanProfile::famouso;
  return s;
}

// docs/can-wire-format.md section 8: priority (7 bits) | fragment | TxNode | etag, the identifier
// each hop's frames carry on the wire.
TEST(FamousoProfile, IdentifiersInFamousosLayout) {
  ChannelSpec sensor = channel("sensor", 1, ChannelClass::nrt, {"bus"}, {"lan"}, 4, Nanos(5ms));
  ChannelSpec command = channel("command", 2, ChannelClass::srt, {"lan"}, {"bus"}, 6, Nanos(10ms), Nanos(50ms));
  ChannelSpec bulk = channel("bulk", 3, ChannelClass::nrt, {"lan"}, {"bus"}, 100, Nanos(100ms));
  const auto e = run({famouso_segment("bus"), dds_segment("lan")}, {sensor, command, bulk},
                     {{"sensor", 16383}, {"command", 300}, {"bulk", 202}}, gateway(500us, 9));
  // The gateway sends `command`, the only SRT channel: plan 0x10, 0x10 in 7 bits, TxNode 9:
  // (0x10 << 22) | (9 << 14) | 300 = 0x0402412C (the document's example).
  const CanHopPlan& cmd = *find_hop(e.channels[1], "bus")->can;
  EXPECT_EQ(cmd.profile, CanProfile::famouso);
  EXPECT_EQ(cmd.priority, 0x10);
  EXPECT_EQ(cmd.can_id, 0x0402412Cu);
  EXPECT_EQ(decode_famouso_id(cmd.can_id), (FamousoIdentifier{0x10, false, 9, 300}));
  // `bulk` (100 B) travels as AFP fragments: the fragment flag is in its identifier. It is the
  // only NRT channel the gateway sends (the FAMOUSO node's `sensor` takes no level even though
  // its period is shorter): plan 0xF0, 0x78 in 7 bits.
  const CanHopPlan& frag = *find_hop(e.channels[2], "bus")->can;
  EXPECT_GT(frag.frames_per_event, 1u);
  EXPECT_EQ(frag.priority, 0x78);
  EXPECT_EQ(frag.can_id, (0x78u << 22) | (1u << 21) | (9u << 14) | 202u);
  // A FAMOUSO node publishes `sensor` at its fixed 0x7D, with a TxNode from the CCP broker: the
  // analysis takes the last one it assigns (0x7E).
  const CanHopPlan& up = *find_hop(e.channels[0], "bus")->can;
  EXPECT_EQ(up.priority, kFamousoProtocolPriority);
  EXPECT_EQ(decode_famouso_id(up.can_id), (FamousoIdentifier{0x7D, false, 0x7E, 16383}));
  // The default profile keeps its own layout on the same set.
  const auto plain = run({can_segment("bus"), dds_segment("lan")}, {sensor, command, bulk},
                         {{"sensor", 16383}, {"command", 300}, {"bulk", 202}}, gateway(500us, 9));
  const CanHopPlan& plain_cmd = *find_hop(plain.channels[1], "bus")->can;
  EXPECT_EQ(plain_cmd.profile, CanProfile::cosmic);
  EXPECT_EQ(plain_cmd.can_id, encode_can_id(CanIdentifier{0x10, 9, 300}));
}

// Beyond 8 NRT channels the last 7-bit level is shared and the bus orders its frames by TxNode
// and etag: the analysis must see that order, not the 8-bit plan's.
TEST(FamousoProfile, SharedLevelsAreAnalysedInWireOrder) {
  std::vector<ChannelSpec> channels;
  EtagMap etags;
  for (int i = 0; i < 10; ++i) {
    const std::string name = "n" + std::to_string(i);
    channels.push_back(
        channel(name, 100 + i, ChannelClass::nrt, {"lan"}, {"bus"}, 8, Nanos(10ms) + Nanos(i * 1'000'000)));
    etags[name] = static_cast<std::uint16_t>(1000 - 10 * i);  // the later the deadline, the lower the etag
  }
  const auto e = run({famouso_segment("bus"), dds_segment("lan")}, channels, etags, gateway(500us, 9));
  auto plan = [&](int i) { return *find_hop(e.channels[static_cast<std::size_t>(i)], "bus")->can; };
  for (int i = 0; i < 7; ++i) EXPECT_EQ(plan(i).priority, 0x78 + i) << i;
  for (int i = 7; i < 10; ++i) EXPECT_EQ(plan(i).priority, 0x7F) << i;
  // On 0x7F the lowest etag wins: n9 before n8 before n7.
  EXPECT_LT(plan(9).can_id, plan(8).can_id);
  EXPECT_LT(plan(8).can_id, plan(7).can_id);
  ASSERT_TRUE(plan(9).response_time && plan(7).response_time);
  // 500 kbit/s, 8 B: 320 us a frame; each is released up to lan's 1 ms + residence 0.5 ms late
  // (jitter 1.5 ms). n7 waits for n0..n6, n8 and n9 (9 frames), then sends: 1.5 + 3.2 ms; n9 for
  // one frame of n7 or n8 already on the bus and n0..n6, then sends: 1.5 + 2.88 ms.
  EXPECT_EQ(*plan(7).response_time, Nanos(4'700'000));
  EXPECT_EQ(*plan(9).response_time, Nanos(4'380'000));
}

// An HRT channel a FAMOUSO node publishes travels at 0x7D: every frame the gateway sends on an
// HRT or SRT channel wins over it, and admission counts that.
TEST(FamousoProfile, ChannelsNodesPublishAreAnalysedAtTheirPriority) {
  // 125 kbit/s, 8 B frames of 1.28 ms. Default profile: `brake` (HRT) has the highest priority,
  // R = blocking by one SRT frame 1.28 + 1.28 = 2.56 ms, end to end 2.56 + 0.5 + 0.1 = 3.16 ms
  // <= 4 ms. FAMOUSO: it goes at 0x7D behind the three SRT frames the gateway sends:
  // R = 3 * 1.28 + 1.28 = 5.12 ms > 4 ms, rejected.
  const std::vector<ChannelSpec> channels{
      channel("brake", 1, ChannelClass::hrt, {"bus"}, {"lan"}, 8, Nanos(10ms), Nanos(4ms)),
      channel("steer", 2, ChannelClass::srt, {"lan"}, {"bus"}, 8, Nanos(10ms), Nanos(20ms)),
      channel("turn", 3, ChannelClass::srt, {"lan"}, {"bus"}, 8, Nanos(10ms), Nanos(20ms)),
      channel("lift", 4, ChannelClass::srt, {"lan"}, {"bus"}, 8, Nanos(10ms), Nanos(20ms))};
  const auto plain = run({can_segment("bus", 125'000), dds_segment("lan", 100us)}, channels);
  EXPECT_EQ(find_hop(plain.channels[0], "bus")->can->response_time, Nanos(2'560'000));
  EXPECT_EQ(plain.channels[0].verdict, Verdict::bound) << reasons_text(plain.channels[0]);
  const auto e = run({famouso_segment("bus", 125'000), dds_segment("lan", 100us)}, channels);
  const ChannelReport& brake = e.channels[0];
  EXPECT_EQ(find_hop(brake, "bus")->can->priority, kFamousoProtocolPriority);
  EXPECT_EQ(find_hop(brake, "bus")->can->response_time, Nanos(5'120'000));
  EXPECT_EQ(brake.verdict, Verdict::rejected);
  EXPECT_TRUE(has_reason(brake, "R = 5.12 ms > reaction_time 4 ms on bus")) << reasons_text(brake);
}

}  // namespace
}  // namespace cosmic

// The real-time forwarding plane with its lane threads running: class and segment isolation,
// runtime verification against admission's promises, and route churn under traffic.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <thread>

#include "cosmic/can_buffering.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"
#include "cosmic/router.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

class RecordingLogger final : public Logger {
 public:
  void log(LogLevel level, std::string_view message) override {
    std::lock_guard lock(mutex);
    lines.emplace_back(std::string(level >= LogLevel::warning ? "warning" : "info") + ": " + std::string(message));
  }
  std::size_t count(std::string_view needle) {
    std::lock_guard lock(mutex);
    return static_cast<std::size_t>(std::count_if(
        lines.begin(), lines.end(), [&](const std::string& l) { return l.find(needle) != std::string::npos; }));
  }
  std::mutex mutex;
  std::vector<std::string> lines;
};

// A transport whose NRT sends block until released, while HRT and SRT sends go through: an NRT
// write stuck in a driver. Counts what it sent per channel.
class StuckNrtAdapter final : public SegmentAdapter {
 public:
  explicit StuckNrtAdapter(std::map<ChannelId, ChannelClass> classes) : classes_(std::move(classes)) {}
  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent& event) override {
    std::unique_lock lock(mutex_);
    if (classes_.at(event.channel) == ChannelClass::nrt) {
      ++nrt_in_send_;
      changed_.notify_all();
      changed_.wait(lock, [&] { return released_; });
    }
    ++sent_[event.channel];
    changed_.notify_all();
    return SendStatus::sent;
  }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override { return {}; }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override { release(); }

  void release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }
  bool wait_for(ChannelId channel, std::size_t count, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return sent_[channel] >= count; });
  }
  bool wait_nrt_stuck(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return nrt_in_send_ > 0; });
  }
  std::size_t sent(ChannelId channel) {
    std::lock_guard lock(mutex_);
    return sent_[channel];
  }

 private:
  std::map<ChannelId, ChannelClass> classes_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<ChannelId, std::size_t> sent_;
  std::size_t nrt_in_send_ = 0;
  bool released_ = false;
};

ChannelSpec spec_of(const std::string& name, std::uint64_t subject, ChannelClass cls) {
  ChannelSpec c;
  c.name = name;
  c.subject = subject;
  c.cls = cls;
  c.payload = 64;
  return c;
}

void inject(Router& router, std::size_t segment, ChannelId id, std::uint64_t subject) {
  EventHeader header;
  header.subject = subject;
  const std::uint8_t payload[4] = {1, 2, 3, 4};
  router.inbox(segment).on_event(InboundEvent{id, header, payload, steady_now()});
}

TEST(ForwardingTest, NrtFloodStuckInTheTransportNeverDelaysOrDropsHrtOnTheSameSegment) {
  StuckNrtAdapter out({{1, ChannelClass::nrt}, {2, ChannelClass::hrt}});
  MemoryAdapter in("in");
  RouterLimits limits;
  limits.nrt_queue = 16;
  Router router(GatewayIdentity{9, "gw"}, 2, limits);
  router.set_segment(0, "in", &in);
  router.set_segment(1, "out", &out);
  router.apply({Route{1, spec_of("bulk", 11, ChannelClass::nrt), {0}, {1}},
                Route{2, spec_of("brake", 22, ChannelClass::hrt), {0}, {1}}});
  for (int i = 0; i < 100; ++i) inject(router, 0, 1, 11);  // 2x more than the NRT lane holds
  ASSERT_TRUE(out.wait_nrt_stuck(5000ms));
  for (int i = 0; i < 50; ++i) inject(router, 0, 2, 22);
  // Every HRT event leaves while an NRT send is stuck and the NRT lane is full.
  EXPECT_TRUE(out.wait_for(2, 50, 5000ms));
  EXPECT_EQ(out.sent(1), 0u);
  const auto snap = router.snapshot();
  const auto& brake = snap[1];
  ASSERT_EQ(brake.name, "brake");
  for (const auto& seg : brake.segments) {
    for (const auto count : seg.dropped) EXPECT_EQ(count, 0u) << seg.segment;
  }
  EXPECT_GT(snap[0].segments[1].dropped[static_cast<std::size_t>(DropReason::queue_full)], 0u);
  out.release();
  router.stop();
}

TEST(ForwardingTest, BlockedSegmentDelaysOnlyItsOwnLanes) {
  MemoryAdapter in("in");
  MemoryAdapter slow("slow");
  MemoryAdapter fast("fast");
  Router router(GatewayIdentity{9, "gw"}, 3);
  router.set_segment(0, "in", &in);
  router.set_segment(1, "slow", &slow);
  router.set_segment(2, "fast", &fast);
  ChannelSpec both = spec_of("speed", 33, ChannelClass::hrt);
  router.apply({Route{1, both, {0}, {1, 2}}});
  ChannelBinding binding{1, both, HopRole::subscriber, std::nullopt};
  slow.start(router.inbox(1));
  fast.start(router.inbox(2));
  slow.configure({&binding, 1});
  fast.configure({&binding, 1});
  slow.hold_sends(true);  // a stuck driver on one segment
  for (int i = 0; i < 20; ++i) inject(router, 0, 1, 33);
  EXPECT_EQ(fast.wait_sent(20, 5s), 20u);
  slow.hold_sends(false);
  EXPECT_EQ(slow.wait_sent(20, 5s), 20u);
  router.stop();
}

TEST(ForwardingTest, ResidenceAndDeadlineMissesAreCountedPerHop) {
  MemoryAdapter in("in");
  MemoryAdapter out("out");
  RouterLimits limits;
  limits.threaded = false;
  limits.residence_bound = Nanos(1);  // nothing can leave within 1 ns: every event misses
  Router router(GatewayIdentity{9, "gw"}, 2, limits);
  router.set_segment(0, "in", &in);
  router.set_segment(1, "out", &out);
  ChannelSpec spec = spec_of("distance", 44, ChannelClass::hrt);
  spec.reaction_time = Nanos(5'000'000);
  router.apply({Route{1, spec, {0}, {1}}});
  ChannelBinding binding{1, spec, HopRole::subscriber, std::nullopt};
  out.start(router.inbox(1));
  out.configure({&binding, 1});
  EventHeader fresh;
  fresh.subject = 44;
  EventHeader late = fresh;
  late.origin = 0x77;
  late.sequence = 1;
  late.age_ns = 6'000'000;  // arrived already older than its reaction time
  const std::uint8_t payload[2] = {1, 2};
  router.inbox(0).on_event(InboundEvent{1, fresh, payload, steady_now()});
  router.inbox(0).on_event(InboundEvent{1, late, payload, steady_now()});
  ASSERT_EQ(router.run_once(10), 2u);
  const auto snap = router.snapshot();
  ASSERT_EQ(snap.size(), 1u);
  const auto& hop = snap[0].segments[1];
  ASSERT_TRUE(hop.egress.has_value());
  EXPECT_EQ(hop.egress->events, 2u);
  EXPECT_EQ(hop.egress->residence_miss, 2u);
  EXPECT_EQ(hop.egress->deadline_miss, 1u);
  EXPECT_GT(hop.egress->residence_max.count(), 0);
  EXPECT_EQ(snap[0].residence_miss, 2u);
  EXPECT_EQ(snap[0].deadline_miss, 1u);
}

// A CAN segment's egress lanes hold what its bus carries in kCanHold (egress_lane_floor: 5,320
// frames at 1 Mbit/s, beyond the NRT class depth of 1,024): a burst forwarded to it while the
// lane's send is stuck is queued whole, and only what passes that is queue_full.
TEST(ForwardingTest, ACanSegmentsLanesHoldWhatItsBusCarriesInTheHold) {
  RecordingLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  StuckNrtAdapter* stuck = nullptr;
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        if (spec.type == SegmentType::can) {
          auto adapter = std::make_unique<StuckNrtAdapter>(std::map<ChannelId, ChannelClass>{{1, ChannelClass::nrt}});
          stuck = adapter.get();
          return adapter;
        }
        auto adapter = std::make_unique<MemoryAdapter>(spec.name);
        adapters[spec.name] = adapter.get();
        return adapter;
      },
      log, 0x42);
  const auto parsed = parse_config(R"(
gateway: {name: gw}
segments:
  - {name: lan, type: dds}
  - {name: body, type: can, interface: can9, bitrate: 1Mbit/s}
channels:
  - {name: bulk, subject: 7, class: nrt, payload: 4B, publishers: [lan], subscribers: [body]}
)",
                                   "can.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.errors[0].to_string();
  ASSERT_TRUE(gateway.start(parsed.config).applied);
  ASSERT_NE(stuck, nullptr);
  const SegmentSpec& body = parsed.config.segments[1];
  const std::size_t floor = egress_lane_floor(body);
  ASSERT_GT(floor, RouterLimits{}.nrt_queue);
  ASSERT_TRUE(adapters["lan"]->inject("bulk", {0, 0, 0, 0}));
  ASSERT_TRUE(stuck->wait_nrt_stuck(5000ms));  // the lane holds the first event in its send
  for (std::size_t i = 1; i <= floor + 10; ++i) {
    const auto n = static_cast<std::uint32_t>(i);
    ASSERT_TRUE(
        adapters["lan"]->inject("bulk", {static_cast<std::uint8_t>(n), static_cast<std::uint8_t>(n >> 8), 0, 0}));
  }
  auto stats = gateway.channel_stats();
  ASSERT_EQ(stats.size(), 1u);
  const auto queue_full = [&] {
    const auto snapshot = gateway.router().snapshot();  // the segments below live in it
    for (const auto& seg : snapshot.at(0).segments)
      if (seg.segment == "body") return seg.dropped[static_cast<std::size_t>(DropReason::queue_full)];
    return std::uint64_t{0};
  };
  EXPECT_EQ(queue_full(), 10u) << "the lane held " << floor << " behind the one in its send";
  stuck->release();
  EXPECT_TRUE(stuck->wait_for(1, floor + 1, 10000ms));
  EXPECT_EQ(stuck->sent(1), floor + 1);
  gateway.stop();
}

constexpr const char* kHrtConfig = R"(
gateway: {name: gw, residence_bound: 1ns, clean_interval: 50ms}
segments:
  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
  - {name: rt, type: dds, domain: 1, latency_bound: 1ms, realtime: true}
channels:
  - {name: distance, subject: 7, class: hrt, period: 10ms, reaction_time: 50ms, temp_validity: 1s, payload: 4B, publishers: [lan], subscribers: [rt]}
)";

TEST(ForwardingTest, AnHrtChannelThatMissesIsViolatedLoggedOnceAndBoundAgainAfterACleanInterval) {
  RecordingLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        auto adapter = std::make_unique<MemoryAdapter>(spec.name);
        adapters[spec.name] = adapter.get();
        return adapter;
      },
      log, 0x42);
  const auto parsed = parse_config(kHrtConfig, "hrt.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.errors[0].to_string();
  ASSERT_TRUE(gateway.start(parsed.config).applied);
  ASSERT_EQ(gateway.admission().channels.at(0).verdict, Verdict::bound);
  auto stats = gateway.channel_stats();
  EXPECT_EQ(stats.at(0).runtime_state, RuntimeState::bound);

  ASSERT_TRUE(adapters["lan"]->inject("distance", {1, 2, 3, 4}));
  ASSERT_EQ(adapters["rt"]->wait_sent(1, 5s), 1u);
  const Nanos t0 = steady_now();
  // The miss is counted right after the send returns: wait for it, then judge.
  for (auto deadline = steady_now() + Nanos(5'000'000'000); gateway.channel_stats().at(0).residence_miss == 0;) {
    ASSERT_LT(steady_now(), deadline);
    std::this_thread::yield();
  }
  gateway.refresh_runtime(t0);
  stats = gateway.channel_stats();
  EXPECT_EQ(stats.at(0).runtime_state, RuntimeState::violated);
  EXPECT_EQ(stats.at(0).violations, 1u);
  EXPECT_EQ(gateway.violated_channels(), 1u);
  EXPECT_EQ(log.count("warning: channel distance violated its admitted bounds"), 1u);
  EXPECT_EQ(log.count("> bound 1 ns"), 1u);
  gateway.refresh_runtime(t0 + Nanos(10'000'000));  // no new miss, but the interval is not over
  EXPECT_EQ(gateway.channel_stats().at(0).runtime_state, RuntimeState::violated);
  EXPECT_EQ(log.count("violated its admitted bounds"), 1u);  // once per episode
  gateway.refresh_runtime(t0 + Nanos(60'000'000));           // a clean interval later
  EXPECT_EQ(gateway.channel_stats().at(0).runtime_state, RuntimeState::bound);
  EXPECT_EQ(gateway.violated_channels(), 0u);
  EXPECT_EQ(log.count("within its admitted bounds again"), 1u);
  gateway.stop();
}

// A route applied afresh (the channel changed on reload) starts with zero counters; its violation
// still ends only after a clean interval, not at the next judgement.
TEST(ForwardingTest, AViolatedChannelStaysViolatedWhenItsRouteIsAppliedAfresh) {
  RecordingLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        auto adapter = std::make_unique<MemoryAdapter>(spec.name);
        adapters[spec.name] = adapter.get();
        return adapter;
      },
      log, 0x44);
  ASSERT_TRUE(gateway.start(parse_config(kHrtConfig, "hrt.yaml").config).applied);
  ASSERT_TRUE(adapters["lan"]->inject("distance", {1, 2, 3, 4}));
  ASSERT_EQ(adapters["rt"]->wait_sent(1, 5s), 1u);
  for (auto deadline = steady_now() + Nanos(5'000'000'000); gateway.channel_stats().at(0).residence_miss == 0;) {
    ASSERT_LT(steady_now(), deadline);
    std::this_thread::yield();
  }
  const Nanos t0 = steady_now();
  gateway.refresh_runtime(t0);
  ASSERT_EQ(gateway.channel_stats().at(0).runtime_state, RuntimeState::violated);

  std::string changed = kHrtConfig;
  changed.replace(changed.find("temp_validity: 1s"), 17, "temp_validity: 2s");
  ASSERT_TRUE(gateway.reload(parse_config(changed, "hrt.yaml").config).applied);
  ASSERT_EQ(gateway.channel_stats().at(0).residence_miss, 0u);  // a fresh route: fresh counters
  gateway.refresh_runtime(t0 + Nanos(10'000'000));
  EXPECT_EQ(gateway.channel_stats().at(0).runtime_state, RuntimeState::violated);
  EXPECT_EQ(gateway.violated_channels(), 1u);
  gateway.refresh_runtime(t0 + Nanos(60'000'000));
  EXPECT_EQ(gateway.channel_stats().at(0).runtime_state, RuntimeState::bound);
  EXPECT_EQ(log.count("violated its admitted bounds"), 1u);
  gateway.stop();
}

TEST(ForwardingTest, AReloadedResidenceBoundIsWhatTheLanesCheck) {
  RecordingLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        auto adapter = std::make_unique<MemoryAdapter>(spec.name);
        adapters[spec.name] = adapter.get();
        return adapter;
      },
      log, 0x43);
  ASSERT_TRUE(gateway.start(parse_config(kHrtConfig, "hrt.yaml").config).applied);
  std::string relaxed = kHrtConfig;
  relaxed.replace(relaxed.find("residence_bound: 1ns"), 20,
                  "residence_bound: 40ms");  // 1 + 40 + 1 ms <= reaction_time 50 ms
  const auto reloaded = parse_config(relaxed, "hrt.yaml");
  ASSERT_TRUE(reloaded.ok());
  ASSERT_TRUE(gateway.reload(reloaded.config).applied);
  // Three events (what the channel's rate policing lets through at once): under the old bound
  // (1 ns) every one misses; under the reloaded one (40 ms) at most one that a loaded host stalled
  // that long (a fresh-clone run once saw one event miss it).
  constexpr std::size_t kEvents = 3;
  for (std::size_t i = 0; i < kEvents; ++i) {
    ASSERT_TRUE(adapters["lan"]->inject("distance", {1, 2, 3, 4}));
    ASSERT_EQ(adapters["rt"]->wait_sent(i + 1, 5s), i + 1);
  }
  for (auto deadline = steady_now() + Nanos(5'000'000'000);
       gateway.channel_stats().at(0).segments.back().egress->events < kEvents;) {
    ASSERT_LT(steady_now(), deadline);
    std::this_thread::yield();
  }
  EXPECT_LE(gateway.channel_stats().at(0).residence_miss, 1u);
  gateway.stop();
}

// Producers on several threads, the lane threads, and the control thread replacing the route
// table all at once (run under ThreadSanitizer by scripts/test). Every event is either sent or
// counted; nothing crashes or races.
TEST(ForwardingTest, RouteChurnWhileProducersAndLanesRun) {
  MemoryAdapter in("in");
  MemoryAdapter out("out");
  Router router(GatewayIdentity{9, "gw"}, 2);
  router.set_segment(0, "in", &in);
  router.set_segment(1, "out", &out);
  std::vector<ChannelBinding> bindings;
  std::vector<Route> routes;
  for (ChannelId id = 1; id <= 4; ++id) {
    ChannelSpec spec = spec_of("c" + std::to_string(id), 100 + id, static_cast<ChannelClass>(id % 3));
    routes.push_back(Route{id, spec, {0}, {1}});
    bindings.push_back(ChannelBinding{id, spec, HopRole::subscriber, std::nullopt});
  }
  out.start(router.inbox(1));
  out.configure(bindings);
  router.apply(routes);
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> injected{0};
  std::vector<std::thread> producers;
  for (int p = 0; p < 3; ++p) {
    producers.emplace_back([&, p] {
      for (int i = 0; i < 3000; ++i) {
        const ChannelId id = 1 + static_cast<ChannelId>((i + p) % 4);
        inject(router, 0, id, 100 + id);
        injected.fetch_add(1);
      }
    });
  }
  std::thread churn([&] {
    for (int round = 0; !done.load(); ++round) {
      std::vector<Route> next = routes;
      if (round % 2 == 0) next.pop_back();  // unbind c4, then bind it again
      router.apply(next);
      std::this_thread::yield();
    }
  });
  for (auto& t : producers) t.join();
  done = true;
  churn.join();
  router.apply(routes);
  for (auto deadline = steady_now() + Nanos(5'000'000'000); router.queued() > 0;) {
    ASSERT_LT(steady_now(), deadline);
    std::this_thread::yield();
  }
  EXPECT_EQ(injected.load(), 9000u);
  EXPECT_LE(out.sent().size(), 9000u);
  EXPECT_GT(out.sent().size(), 0u);
  router.stop();
}

}  // namespace
}  // namespace cosmic

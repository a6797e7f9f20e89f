#include "cosmic/residence_calibration.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "cosmic/gateway.hpp"
#include "cosmic/router.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {
namespace {

constexpr std::size_t kIngress = 0;
constexpr std::size_t kEgress = 1;
constexpr ChannelId kHrtChannel = 1;
constexpr ChannelId kFloodChannel = 2;
constexpr std::uint64_t kHrtSubject = 0xCA11B0001;
constexpr std::uint64_t kFloodSubject = 0xCA11B0002;

// A transport whose send() returns at once: what remains is the gateway's own residence.
class NullTransport final : public SegmentAdapter {
 public:
  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent&) override { return SendStatus::sent; }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override { return {}; }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override {}
};

ChannelSpec channel(const char* name, std::uint64_t subject, ChannelClass cls, std::size_t payload) {
  ChannelSpec spec;
  spec.name = name;
  spec.subject = subject;
  spec.cls = cls;
  spec.payload = payload;
  spec.publishers = {"in"};
  spec.subscribers = {"out"};
  return spec;
}

// Offers NRT events as fast as the router takes them until `running` falls.
void flood(Router& router, const std::atomic<bool>& running, std::size_t payload_bytes, std::uint64_t& offered) {
  const std::vector<std::uint8_t> payload(payload_bytes, 0x5A);
  EventHeader header{};
  header.subject = kFloodSubject;
  while (running.load(std::memory_order_relaxed)) {
    router.inbox(kIngress).on_event(InboundEvent{kFloodChannel, header, payload, steady_now()});
    ++offered;
  }
}

// HRT events at the configured rate, paced on absolute times so a late wake-up does not drift.
std::uint64_t offer_hrt(Router& router, const CalibrationOptions& options) {
  const std::vector<std::uint8_t> payload(options.hrt_payload, 0x11);
  EventHeader header{};
  header.subject = kHrtSubject;
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / std::max(1.0, options.hrt_rate_hz)));
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + options.phase_duration;
  std::uint64_t offered = 0;
  for (auto next = start; next < end; next += period) {
    std::this_thread::sleep_until(next);
    router.inbox(kIngress).on_event(InboundEvent{kHrtChannel, header, payload, steady_now()});
    ++offered;
  }
  return offered;
}

CalibrationPhase run_phase(const GatewaySpec& gateway, const CalibrationOptions& options, bool with_flood,
                           std::vector<std::string>& problems) {
  NullTransport in;
  NullTransport out;
  Router router(GatewayIdentity{0xCA11B, "calibrate"}, 2, router_limits(gateway));
  router.set_segment(kIngress, "in", &in);
  router.set_segment(kEgress, "out", &out);
  std::vector<Route> routes{
      Route{kHrtChannel, channel("hrt", kHrtSubject, ChannelClass::hrt, options.hrt_payload), {kIngress}, {kEgress}}};
  if (with_flood) {
    routes.push_back(Route{kFloodChannel,
                           channel("flood", kFloodSubject, ChannelClass::nrt, options.flood_payload),
                           {kIngress},
                           {kEgress}});
  }
  router.apply(routes);

  CalibrationPhase phase;
  phase.name = with_flood ? "nrt-flood" : "idle";
  std::atomic<bool> flooding{with_flood};
  std::thread flooder;
  if (with_flood) {
    flooder = std::thread([&] {
      apply_thread_policy(ThreadPolicy{"calib-flood", 0, 0, {}});
      flood(router, flooding, options.flood_payload, phase.flood_offered);
    });
  }
  // The HRT producer plays an adapter's receive thread, so it runs as gateway.realtime says.
  std::thread producer([&] {
    const RealtimeSpec& rt = gateway.realtime;
    for (auto& p : apply_thread_policy(ThreadPolicy{"calib-rx", rt.receive_priority, 0, rt.cpus.receive}))
      problems.push_back("receive thread: " + p);
    phase.hrt_events = offer_hrt(router, options);
  });
  producer.join();
  flooding.store(false, std::memory_order_relaxed);
  if (flooder.joinable()) flooder.join();
  router.stop();
  for (auto& p : router.take_thread_problems()) problems.push_back(std::move(p));

  for (const auto& stats : router.snapshot()) {
    const auto& hop = stats.segments.back();
    if (stats.name == "hrt" && hop.egress) {
      phase.p50 = hop.egress->residence_p50;
      phase.p99 = hop.egress->residence_p99;
      phase.p999 = hop.egress->residence_p999;
      phase.max = hop.egress->residence_max;
      phase.residence_miss = hop.egress->residence_miss;
      phase.hrt_sent = hop.egress->events;
    } else if (stats.name == "flood") {
      phase.flood_sent = hop.tx;
      phase.flood_queue_full = hop.dropped[static_cast<std::size_t>(DropReason::queue_full)];
    }
  }
  return phase;
}

}  // namespace

CalibrationResult calibrate_residence(const GatewaySpec& gateway, const CalibrationOptions& options) {
  CalibrationResult result;
  result.residence_bound = gateway.residence_bound;
  for (const bool with_flood : {false, true}) {
    result.phases.push_back(run_phase(gateway, options, with_flood, result.thread_problems));
    result.worst_p999 = std::max(result.worst_p999, result.phases.back().p999);
  }
  // Both phases run the same threads: a problem is worth saying once.
  std::sort(result.thread_problems.begin(), result.thread_problems.end());
  result.thread_problems.erase(std::unique(result.thread_problems.begin(), result.thread_problems.end()),
                               result.thread_problems.end());
  return result;
}

}  // namespace cosmic

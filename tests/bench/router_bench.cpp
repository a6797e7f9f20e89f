// cosmic_router_bench: Google Benchmark micro-benchmarks of the router's hot path (no network).
// One NRT channel "bench" from segment "in" to segment "out", 64-byte events, as in
// tests/runtime/router_test.cpp. The egress side is a counting adapter (MemoryAdapter records
// every event it is sent, which would measure vector growth, not the router).
//
//   BM_OnEventDispatch/B/foreign  router.inbox().on_event() B times, then run_once(B), one
//                                 thread: queue push + pop + policies + dispatch + statistics.
//                                 foreign=1: the events carry another gateway's origin and
//                                 increasing sequences (duplicate filter path), 0: native source.
//   BM_MemoryAdapterInject/B      the same through MemoryAdapter::inject() (its lock, channel
//                                 lookup by name and payload copy included).
//   BM_Threaded                   a producer thread (the adapter's) feeding the NRT egress lane
//                                 thread: cross-thread hand-off and wake-ups included; real time
//                                 until the last event is sent.
//   BM_HrtResidence/flood         HRT events at 1 kHz through their own lane, idle (flood=0) or
//                                 while a second thread floods an NRT channel to the same
//                                 segment as fast as it can (flood=1); counters: HRT residence
//                                 p50/p99/p99.9/max in microseconds (from the router's own
//                                 histogram) and the NRT events dropped as queue_full.
//   BM_TypedConversion/stage      a typed channel's conversions (issue 35) on one event of a
//                                 10-signal DBC message (8-byte frame): stage 0 the frame into the
//                                 compact layout (the ingress side), 1 the compact event into XCDR2
//                                 of the message's struct (a ROS 2-style DDS hop's egress side), 2
//                                 both.
//   BM_TypedDispatch/B            BM_OnEventDispatch's path for that typed channel: the frame comes
//                                 in on a DBC hop and leaves as XCDR2, both conversions included.
// items_per_second is events per second; ns/event = 1e9 / items_per_second.
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string_view>
#include <thread>
#include <vector>

#include "cosmic/cdr_representation.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/hop_representation.hpp"
#include "cosmic/memory_adapter.hpp"
#include "cosmic/router.hpp"

namespace {

using namespace cosmic;

class CountingAdapter final : public SegmentAdapter {
 public:
  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent& event) override {
    bytes_.fetch_add(event.payload.size(), std::memory_order_relaxed);
    sent_.fetch_add(1, std::memory_order_release);
    return SendStatus::sent;
  }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override {
    AdapterStatistics s;
    s.sent = sent_.load();
    return s;
  }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override {}
  std::uint64_t sent() const { return sent_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> bytes_{0};
};

constexpr ChannelId kChannel = 1;

RouterLimits limits_for(bool threaded) {
  RouterLimits limits;
  limits.threaded = threaded;
  return limits;
}

// The typed channel of BM_TypedConversion and BM_TypedDispatch: a wheel-speed ECU's 10 signals
// (four scaled speeds as float64, gear, mode, two flags, a counter, a scaled temperature).
constexpr std::string_view kTypedDbc = R"(BO_ 416 WheelSpeeds: 8 Ecu
 SG_ SpeedFL : 0|12@1+ (0.1,0) [0|409.5] "km/h" Gw
 SG_ SpeedFR : 12|12@1+ (0.1,0) [0|409.5] "km/h" Gw
 SG_ SpeedRL : 24|12@1+ (0.1,0) [0|409.5] "km/h" Gw
 SG_ SpeedRR : 36|12@1+ (0.1,0) [0|409.5] "km/h" Gw
 SG_ Gear : 48|4@1- (1,0) [-1|6] "" Gw
 SG_ Mode : 52|2@1+ (1,0) [0|3] "" Gw
 SG_ Valid : 54|1@1+ (1,0) [0|1] "" Gw
 SG_ Brake : 55|1@1+ (1,0) [0|1] "" Gw
 SG_ Counter : 56|4@1+ (1,0) [0|15] "" Gw
 SG_ Temp : 60|4@1+ (5,-20) [-20|55] "degC" Gw
)";

struct TypedForms {
  TypedForms() {
    const DbcFile file = parse_dbc(kTypedDbc);
    const DbcMessage& message = file.messages.at(0);
    type = channel_type_from_dbc(message).type;
    frame = std::make_shared<DbcFrameRepresentation>(DbcFrameCodec::make(message, type).value(), "DBC frame",
                                                     RangePolicy::drop);
    cdr = std::make_shared<CdrRepresentation>(
        CdrRepresentation::make(type, DdsRepresentation::xcdr2, CdrExtensibility::final_type).value());
  }
  ChannelType type;
  std::shared_ptr<const Representation> frame;
  std::shared_ptr<const Representation> cdr;
  std::vector<std::uint8_t> wheel_frame = {0x15, 0x36, 0x41, 0x2B, 0x9A, 0x07, 0xF1, 0x93};
};

struct Bench {
  explicit Bench(bool threaded = false, const TypedForms* typed = nullptr)
      : router(GatewayIdentity{0xAAAA, "bench"}, 2, limits_for(threaded)) {
    ChannelSpec spec;
    spec.name = "bench";
    spec.subject = 0x100;
    spec.cls = ChannelClass::nrt;
    spec.payload = 64;
    spec.omission_degree = 3;
    spec.publishers = {"in"};
    spec.subscribers = {"out"};
    router.set_segment(0, "in", &in);
    router.set_segment(1, "out", &out);
    in.start(router.inbox(0));
    out.start(router.inbox(1));
    const ChannelBinding pub{kChannel, spec, HopRole::publisher, std::nullopt};
    const ChannelBinding sub{kChannel, spec, HopRole::subscriber, std::nullopt};
    in.configure(std::span<const ChannelBinding>(&pub, 1));
    out.configure(std::span<const ChannelBinding>(&sub, 1));
    Route route{kChannel, spec, {0}, {1}};
    if (typed != nullptr) {
      route.spec.type = typed->type;
      route.publisher_forms = {typed->frame};
      route.subscriber_forms = {typed->cdr};
    }
    router.apply({route});
  }
  MemoryAdapter in{"in"};
  CountingAdapter out;
  Router router;
  std::vector<std::uint8_t> payload = std::vector<std::uint8_t>(64, 0x5a);
};

void BM_OnEventDispatch(benchmark::State& state) {
  Bench b;
  const auto batch = static_cast<std::size_t>(state.range(0));
  const bool foreign = state.range(1) != 0;
  EventHeader header{};
  header.subject = 0x100;
  if (foreign) {
    header.origin = 0xBBBB;
    header.hop_count = 1;
  }
  std::uint32_t sequence = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < batch; ++i) {
      if (foreign) header.sequence = ++sequence;
      b.router.inbox(0).on_event(InboundEvent{kChannel, header, b.payload, steady_now()});
    }
    benchmark::DoNotOptimize(b.router.run_once(batch));
  }
  if (b.out.sent() != state.iterations() * batch) state.SkipWithError("events were lost");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * batch));
}
BENCHMARK(BM_OnEventDispatch)->ArgsProduct({{1, 64}, {0, 1}})->ArgNames({"batch", "foreign"});

void BM_MemoryAdapterInject(benchmark::State& state) {
  Bench b;
  const auto batch = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    for (std::size_t i = 0; i < batch; ++i) b.in.inject("bench", b.payload);
    benchmark::DoNotOptimize(b.router.run_once(batch));
  }
  if (b.out.sent() != state.iterations() * batch) state.SkipWithError("events were lost");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * batch));
}
BENCHMARK(BM_MemoryAdapterInject)->Arg(1)->Arg(64)->ArgName("batch");

void BM_Threaded(benchmark::State& state) {
  Bench b(true);
  constexpr std::size_t kPerIteration = 10000;
  std::uint64_t total = 0;
  EventHeader header{};
  header.subject = 0x100;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < kPerIteration; ++i) {
      // Stay below the NRT queue bound (1024): measure forwarding, not queue_full drops.
      while (total + i - b.out.sent() >= 1000) std::this_thread::yield();
      b.router.inbox(0).on_event(InboundEvent{kChannel, header, b.payload, steady_now()});
    }
    total += kPerIteration;
    while (b.out.sent() < total) std::this_thread::yield();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  b.router.stop();
  state.SetItemsProcessed(static_cast<std::int64_t>(total));
}
BENCHMARK(BM_Threaded)->UseManualTime()->Unit(benchmark::kMillisecond);

void BM_HrtResidence(benchmark::State& state) {
  Bench b(true);
  ChannelSpec hrt;
  hrt.name = "brake";
  hrt.subject = 0x200;
  hrt.cls = ChannelClass::hrt;
  hrt.payload = 8;
  ChannelSpec nrt;
  nrt.name = "bulk";
  nrt.subject = 0x100;
  nrt.cls = ChannelClass::nrt;
  nrt.payload = 64;
  b.router.apply({Route{1, nrt, {0}, {1}}, Route{2, hrt, {0}, {1}}});
  const bool flood = state.range(0) != 0;
  std::atomic<bool> flooding{flood};
  std::thread flooder([&] {
    EventHeader header{};
    header.subject = 0x100;
    while (flooding.load(std::memory_order_relaxed))
      b.router.inbox(0).on_event(InboundEvent{1, header, b.payload, steady_now()});
  });
  EventHeader header{};
  header.subject = 0x200;
  const std::uint8_t payload[8] = {};
  for (auto _ : state) {
    for (int i = 0; i < 200; ++i) {
      b.router.inbox(0).on_event(InboundEvent{2, header, payload, steady_now()});
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  flooding = false;
  flooder.join();
  b.router.stop();
  for (const auto& channel : b.router.snapshot()) {
    if (channel.name == "brake") {
      const auto& hop = *channel.segments.back().egress;
      state.counters["hrt_p50_us"] = static_cast<double>(hop.residence_p50.count()) / 1e3;
      state.counters["hrt_p99_us"] = static_cast<double>(hop.residence_p99.count()) / 1e3;
      state.counters["hrt_p999_us"] = static_cast<double>(hop.residence_p999.count()) / 1e3;
      state.counters["hrt_max_us"] = static_cast<double>(hop.residence_max.count()) / 1e3;
      state.counters["hrt_events"] = static_cast<double>(hop.events);
    } else {
      state.counters["nrt_queue_full"] =
          static_cast<double>(channel.segments.back().dropped[static_cast<std::size_t>(DropReason::queue_full)]);
      state.counters["nrt_sent"] = static_cast<double>(channel.segments.back().tx);
    }
  }
}
BENCHMARK(BM_HrtResidence)->Arg(0)->Arg(1)->ArgName("flood")->Iterations(5)->Unit(benchmark::kMillisecond);

void BM_TypedConversion(benchmark::State& state) {
  const TypedForms f;
  std::vector<std::uint8_t> compact(f.frame->max_compact_size());
  std::vector<std::uint8_t> wire(f.cdr->max_wire_size());
  const std::int64_t stage = state.range(0);
  if (!f.frame->to_compact(f.wheel_frame, compact).ok()) state.SkipWithError("the frame did not convert");
  for (auto _ : state) {
    if (stage != 1) benchmark::DoNotOptimize(f.frame->to_compact(f.wheel_frame, compact));
    if (stage != 0) benchmark::DoNotOptimize(f.cdr->from_compact(compact, wire));
    benchmark::ClobberMemory();
  }
  if (!f.cdr->from_compact(compact, wire).ok()) state.SkipWithError("the event did not convert");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}
BENCHMARK(BM_TypedConversion)->Arg(0)->Arg(1)->Arg(2)->ArgName("stage");

void BM_TypedDispatch(benchmark::State& state) {
  const TypedForms f;
  Bench b(false, &f);
  const auto batch = static_cast<std::size_t>(state.range(0));
  EventHeader header{};
  header.subject = 0x100;
  for (auto _ : state) {
    for (std::size_t i = 0; i < batch; ++i)
      b.router.inbox(0).on_event(InboundEvent{kChannel, header, f.wheel_frame, steady_now()});
    benchmark::DoNotOptimize(b.router.run_once(batch));
  }
  if (b.out.sent() != state.iterations() * batch) state.SkipWithError("events were lost");
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * batch));
}
BENCHMARK(BM_TypedDispatch)->Arg(1)->Arg(64)->ArgName("batch");

}  // namespace

BENCHMARK_MAIN();

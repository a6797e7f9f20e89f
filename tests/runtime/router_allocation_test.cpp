// The forwarding path allocates nothing per event once warmed up: every operator new in this
// binary is counted, and N events through the router must not move the count: bytes as they came
// in, and a typed channel's events converted on both hops (issue 35, item 7).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "cosmic/cdr_representation.hpp"
#include "cosmic/dbc.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/hop_representation.hpp"
#include "cosmic/router.hpp"

namespace {
std::atomic<std::size_t> allocations{0};
}  // namespace

// The replacements pair malloc with free on purpose; GCC cannot see that both sides are ours.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
// The non-throwing forms count too (the payload pool allocates with them) and must pair with the
// same free(), or a sanitizer's own operator new meets this operator delete.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace cosmic {
namespace {

// Counts sends without storing them (MemoryAdapter records, which allocates by design).
class CountingAdapter final : public SegmentAdapter {
 public:
  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent&) override {
    ++sent;
    return SendStatus::sent;
  }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override { return {}; }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override {}
  std::size_t sent = 0;
};

TEST(RouterAllocationTest, SteadyStateForwardingDoesNotAllocate) {
  CountingAdapter in;
  CountingAdapter out;
  RouterLimits limits;
  limits.threaded = false;  // run_once() below does the lanes' work on this thread
  Router router(GatewayIdentity{1, "gw"}, 2, limits);
  router.set_segment(0, "in", &in);
  router.set_segment(1, "out", &out);
  ChannelSpec spec;
  spec.name = "speed";
  spec.subject = 5;
  spec.payload = 64;
  spec.cls = ChannelClass::srt;
  spec.temp_validity = Nanos(1'000'000'000);
  spec.publishers = {"in"};
  spec.subscribers = {"out"};
  router.apply({Route{1, spec, {0}, {1}}});
  const std::vector<std::uint8_t> payload(64, 0xAB);
  std::uint32_t sequence = 0;
  auto pump = [&](int events) {
    for (int i = 0; i < events; ++i) {
      EventHeader header;
      header.subject = spec.subject;
      header.origin = 77;
      header.sequence = ++sequence;
      router.inbox(0).on_event(InboundEvent{1, header, payload, steady_now()});
      router.run_once(8);
    }
  };
  pump(2000);  // warm-up: pooled payload buffers grow once
  const std::size_t before = allocations.load();
  pump(10'000);
  EXPECT_EQ(allocations.load() - before, 0u);
  EXPECT_EQ(out.sent, 12'000u);
}

// scripts/bench's typed message: ten signals of a 64-byte CAN FD frame.
constexpr const char* kSample10 = R"(BO_ 1280 Sample10: 64 Bench
 SG_ Stamp : 0|64@1+ (1,0) [0|0] "ns" Sink
 SG_ Speed : 64|16@1+ (0.01,0) [0|0] "km/h" Sink
 SG_ Accel : 80|16@1- (0.001,0) [-32.768|32.767] "m/s2" Sink
 SG_ YawRate : 96|16@1- (0.001,0) [-32.768|32.767] "rad/s" Sink
 SG_ Steer : 112|16@1- (0.01,0) [-327.68|327.67] "deg" Sink
 SG_ Torque : 128|12@1+ (0.5,0) [0|2047.5] "Nm" Sink
 SG_ Voltage : 140|12@1+ (0.01,0) [0|40.95] "V" Sink
 SG_ Gear : 152|8@1- (1,0) [-1|8] "" Sink
 SG_ Mode : 160|4@1+ (1,0) [0|15] "" Sink
 SG_ Valid : 164|1@1+ (1,0) [0|1] "" Sink
)";

// A DBC frame in (to_compact, then the router's check_compact), XCDR2 of the struct out
// (from_compact), every event.
TEST(RouterAllocationTest, TypedForwardingDoesNotAllocate) {
  CountingAdapter in;
  CountingAdapter out;
  RouterLimits limits;
  limits.threaded = false;
  Router router(GatewayIdentity{1, "gw"}, 2, limits);
  router.set_segment(0, "can", &in);
  router.set_segment(1, "dds", &out);
  const DbcFile file = parse_dbc(kSample10);
  ASSERT_EQ(file.messages.size(), 1u);
  const DbcMessage& message = file.messages[0];
  const DbcChannelType typed = channel_type_from_dbc(message);
  ASSERT_TRUE(typed.ok());
  Result<DbcFrameCodec> codec = DbcFrameCodec::make(message, typed.type);
  ASSERT_TRUE(codec.ok()) << codec.error().text;
  Result<CdrRepresentation> cdr =
      CdrRepresentation::make(typed.type, DdsRepresentation::xcdr2, CdrExtensibility::final_type);
  ASSERT_TRUE(cdr.ok()) << cdr.error().text;
  Route route;
  route.id = 1;
  route.spec.name = "sample";
  route.spec.subject = 6;
  route.spec.payload = 64;
  route.spec.type = typed.type;
  route.spec.publishers = {"can"};
  route.spec.subscribers = {"dds"};
  route.publishers = {0};
  route.subscribers = {1};
  route.publisher_forms = {
      std::make_shared<DbcFrameRepresentation>(std::move(codec).value(), "Sample10", RangePolicy::drop)};
  route.subscriber_forms = {std::make_shared<CdrRepresentation>(std::move(cdr).value())};
  router.apply({route});
  std::vector<std::uint8_t> frame(64);
  std::uint32_t sequence = 0;
  auto pump = [&](int events) {
    for (int i = 0; i < events; ++i) {
      for (std::size_t b = 0; b < frame.size(); ++b) frame[b] = static_cast<std::uint8_t>(sequence * 7 + b);
      EventHeader header;
      header.subject = route.spec.subject;
      header.origin = 78;
      header.sequence = ++sequence;
      router.inbox(0).on_event(InboundEvent{1, header, frame, steady_now()});
      router.run_once(8);
    }
  };
  pump(2000);
  const std::size_t before = allocations.load();
  pump(10'000);
  EXPECT_EQ(allocations.load() - before, 0u);
  EXPECT_EQ(out.sent, 12'000u);  // every frame converted and sent: none refused
}

}  // namespace
}  // namespace cosmic

// The forwarding path allocates nothing per event once warmed up: every operator new in this
// binary is counted, and N events through the router must not move the count.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

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

}  // namespace
}  // namespace cosmic

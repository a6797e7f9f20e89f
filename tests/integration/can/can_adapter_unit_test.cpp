// Pieces of the CAN adapter that need no CAN bus: the binding frames (byte-level, as in
// docs/can-wire-format.md), the backlog's priority order, and the adapter's behaviour when its
// interface does not exist (runs on any Linux host, with or without AF_CAN).
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <thread>

#include "can_binding.hpp"
#include "cosmic/can_adapter.hpp"
#include "cosmic/can_wire.hpp"
#include "frame_backlog.hpp"
#include "receive_buffer.hpp"

namespace cosmic {
namespace {

TEST(CanBinding, GetEtagRequestCarriesTheSubjectBigEndian) {
  // cansend vcan0 1FA8C002#0000000100000042 : priority 0xFD, TxNode 0x23, etag 2
  const std::uint32_t id = encode_can_id(CanIdentifier{0xFD, 0x23, kEtagGetEtag});
  EXPECT_EQ(id, 0x1FA8C002u);
  const std::array<std::uint8_t, 8> data{0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x42};
  const auto request = can_binding::decode_get_etag(id, data);
  ASSERT_TRUE(request.has_value());
  EXPECT_EQ(request->requester, 0x23);
  EXPECT_EQ(request->subject, 0x0000000100000042u);
  EXPECT_EQ(can_binding::get_etag_data(0x0000000100000042u), data);
  EXPECT_FALSE(can_binding::decode_get_etag(id, std::span(data).first(7)).has_value());
  EXPECT_FALSE(can_binding::decode_get_etag(encode_can_id(CanIdentifier{0xFD, 0x23, 200}), data).has_value());
}

TEST(CanBinding, SupplyEtagIsTwoFramesWithSubjectHalves) {
  const auto frames = can_binding::supply_etag_data(0x23, 0x3FFF, 0x0102030405060708u);
  EXPECT_EQ(frames[0], (std::array<std::uint8_t, 8>{0x23, 0x00, 0x3F, 0xFF, 0x01, 0x02, 0x03, 0x04}));
  EXPECT_EQ(frames[1], (std::array<std::uint8_t, 8>{0x23, 0x01, 0x3F, 0xFF, 0x05, 0x06, 0x07, 0x08}));
  // Gateway TxNode 1: priority 0xFD | TxNode 1 | etag 3.
  EXPECT_EQ(can_binding::supply_etag_id(1), 0x1FA04003u);
  const auto decoded = can_binding::decode_supply_etag(frames[1]);
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(decoded->requester, 0x23);
  EXPECT_EQ(decoded->part, 1);
  EXPECT_EQ(decoded->etag, 0x3FFF);
}

canfd_frame frame_with(std::uint32_t id, std::uint8_t tag) {
  canfd_frame f{};
  f.can_id = id | CAN_EFF_FLAG;
  f.len = 1;
  f.data[0] = tag;
  return f;
}

TEST(CanBacklog, LowestIdentifierFirstAndFifoWithinOneIdentifier) {
  FrameBacklog backlog(5);
  ASSERT_TRUE(backlog.push(frame_with(0x1E000100, 1), false));  // NRT
  ASSERT_TRUE(backlog.push(frame_with(0x00004101, 2), false));  // HRT
  ASSERT_TRUE(backlog.push(frame_with(0x1E000100, 3), false));  // NRT, after 1
  ASSERT_TRUE(backlog.push(frame_with(0x02004102, 4), false));  // SRT
  ASSERT_TRUE(backlog.push(frame_with(0x1E000100, 5), false));
  EXPECT_FALSE(backlog.push(frame_with(0x00000001, 6), false));  // full
  EXPECT_FALSE(backlog.room_for(1));
  std::vector<int> order;
  while (!backlog.empty()) {
    order.push_back(backlog.top().frame.data[0]);
    backlog.pop();
  }
  EXPECT_EQ(order, (std::vector<int>{2, 4, 1, 3, 5}));
}

// A standard frame beats an extended one with the same 11 base bits (its RTR meets the extended
// frame's recessive SRR), and loses to a lower base: the backlog orders them as the bus does.
TEST(CanBacklog, StandardAndExtendedFramesLeaveInArbitrationOrder) {
  FrameBacklog backlog(4);
  canfd_frame standard{};
  standard.can_id = 0x123;  // base 0x123
  standard.data[0] = 1;
  ASSERT_TRUE(backlog.push(frame_with(0x123u << 18 | 0x5, 2), false));  // base 0x123, extended
  ASSERT_TRUE(backlog.push(standard, false));
  ASSERT_TRUE(backlog.push(frame_with(0x122u << 18 | 0x3FFFF, 3), false));  // base 0x122: first
  std::vector<int> order;
  while (!backlog.empty()) order.push_back(backlog.take().frame.data[0]);
  EXPECT_EQ(order, (std::vector<int>{3, 1, 2}));
}

// The receive thread takes a frame out to write it without the lock; it keeps its place in the
// count meanwhile, and a frame the kernel refused goes back ahead of later frames of its identifier.
TEST(CanBacklog, ARestoredFrameKeepsItsPlaceAheadOfLaterFramesOfItsIdentifier) {
  FrameBacklog backlog(3);
  ASSERT_TRUE(backlog.push(frame_with(0x100, 1), false));
  const FrameBacklog::Entry taken = backlog.take();
  ASSERT_TRUE(backlog.push(frame_with(0x100, 2), false));
  ASSERT_TRUE(backlog.push(frame_with(0x100, 3), false));
  EXPECT_FALSE(backlog.room_for(1));  // the taken frame holds its place
  backlog.restore(taken);
  EXPECT_EQ(backlog.size(), 3u);
  EXPECT_EQ(backlog.taken(), 0u);
  std::vector<int> order;
  while (!backlog.empty()) order.push_back(backlog.take().frame.data[0]);
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3}));
}

// Frames the kernel took free their places; the backlog never exceeds its capacity.
TEST(CanBacklog, SettledFramesFreeTheirPlaces) {
  FrameBacklog backlog(2);
  ASSERT_TRUE(backlog.push(frame_with(0x100, 1), false));
  ASSERT_TRUE(backlog.push(frame_with(0x100, 2), false));
  (void)backlog.take();
  (void)backlog.take();
  EXPECT_FALSE(backlog.room_for(1));
  backlog.settle(1);
  EXPECT_TRUE(backlog.room_for(1));
  EXPECT_FALSE(backlog.room_for(2));
  backlog.settle(5);  // never below zero
  EXPECT_EQ(backlog.taken(), 0u);
  EXPECT_TRUE(backlog.room_for(2));
}

// The receive socket is sized for the bus: what it carries in kReceiveHold at its shortest frame.
TEST(CanReceiveBuffer, HoldsWhatTheBusCarriesInTheHoldTime) {
  CanSegmentProperties bus;
  bus.bitrate = BitRate{1'000'000};
  EXPECT_EQ(receive_buffer_frames(bus), 5320u);  // 1e6 / 47 frames/s for 250 ms, rounded up
  bus.bitrate = BitRate{125'000};
  EXPECT_EQ(receive_buffer_frames(bus), 665u);
  bus.bitrate = BitRate{10'000};
  EXPECT_EQ(receive_buffer_frames(bus), kMinReceiveFrames);
  // The request is half the memory (the kernel doubles it); what a granted buffer holds.
  EXPECT_EQ(receive_buffer_request(5320), 5320 * 768 / 2);
  EXPECT_EQ(frames_held(5320 * 768), 5320u);
  EXPECT_EQ(frames_held(212992), 277u);  // Linux's default buffer
}

class NullSink final : public EventSink {
 public:
  void on_event(const InboundEvent&) override { ++events; }
  void on_problem(ChannelId, InboundProblem) override { ++problems; }
  int events = 0;
  int problems = 0;
};

class NullLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

SegmentSpec can_segment(const std::string& interface) {
  SegmentSpec spec;
  spec.name = "bus";
  spec.type = SegmentType::can;
  spec.can.interface = interface;
  return spec;
}

TEST(CanAdapterWithoutBus, StartsAndReportsAMissingInterface) {
  NullLogger log;
  NullSink sink;
  auto adapter = make_can_adapter(can_segment("nosuchcan7"), GatewayIdentity{1, "gw"}, log);
  ASSERT_TRUE(adapter);
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  ASSERT_TRUE(adapter->start(sink).ok);
  const HealthReport health = adapter->health();
  EXPECT_EQ(health.state, SegmentHealth::down);
  EXPECT_EQ(health.detail, "no such interface nosuchcan7");
  // Sending while the bus is missing fails cleanly and is counted.
  ChannelBinding binding;
  binding.id = 5;
  binding.spec.name = "c";
  binding.spec.subject = 0x42;
  binding.spec.payload = 4;
  binding.role = HopRole::subscriber;
  binding.can = CanHopPlan{};
  binding.can->etag = 200;
  binding.can->can_id = encode_can_id(CanIdentifier{0x10, 1, 200});
  EXPECT_TRUE(adapter->configure(std::span(&binding, 1)).ok);
  const std::array<std::uint8_t, 4> payload{1, 2, 3, 4};
  EXPECT_EQ(adapter->send(OutboundEvent{5, {}, payload}), SendStatus::failed);
  EXPECT_EQ(adapter->statistics().send_errors, 1u);
  adapter->stop();
  adapter->stop();  // idempotent
}

// Issue 22, item 12: the one configure() contract (SegmentAdapter::configure): each binding the
// adapter cannot carry is named in Status::refused with its reason, and only those.
TEST(CanAdapterWithoutBus, RejectsBindingsItCannotCarry) {
  NullLogger log;
  NullSink sink;
  auto adapter = make_can_adapter(can_segment("nosuchcan7"), GatewayIdentity{1, "gw"}, log);
  ASSERT_TRUE(adapter->start(sink).ok);  // a segment that is not started refuses every binding
  ChannelBinding reserved;
  reserved.id = 1;
  reserved.spec.name = "reserved";
  reserved.can = CanHopPlan{};
  reserved.can->etag = 3;
  ChannelBinding no_plan;
  no_plan.id = 2;
  no_plan.spec.name = "noplan";
  ChannelBinding fine;
  fine.id = 3;
  fine.spec.name = "fine";
  fine.spec.payload = 4;
  fine.role = HopRole::subscriber;
  fine.can = CanHopPlan{};
  fine.can->etag = 200;
  fine.can->can_id = encode_can_id(CanIdentifier{0x10, 1, 200});
  const std::array bindings{reserved, no_plan, fine};
  const Status status = adapter->configure(bindings);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.error.find("reserved"), std::string::npos);
  EXPECT_NE(status.error.find("no CAN plan"), std::string::npos);
  ASSERT_EQ(status.refused.size(), 2u) << status.error;
  EXPECT_EQ(status.refused[0].channel, 1u);
  EXPECT_EQ(status.refused[0].reason, "etag 3 is reserved or out of range");
  EXPECT_EQ(status.refused[1].channel, 2u);
  EXPECT_EQ(status.refused[1].reason, "no CAN plan");
}

// Admission plans each hop in its segment's identifier layout; a plan for the other layout would
// put the wrong priority (or the fragment flag) on the wire, so it is refused.
TEST(CanAdapterWithoutBus, RefusesAPlanInAnotherLayout) {
  NullLogger log;
  SegmentSpec famouso = can_segment("nosuchcan7");
  famouso.can.profile = CanProfile::famouso;
  NullSink sink;
  auto adapter = make_can_adapter(famouso, GatewayIdentity{1, "gw"}, log);
  ASSERT_TRUE(adapter->start(sink).ok);
  ChannelBinding binding;
  binding.id = 5;
  binding.spec.name = "c";
  binding.spec.subject = 0x42;
  binding.spec.payload = 4;
  binding.role = HopRole::subscriber;
  binding.can = CanHopPlan{};
  binding.can->etag = 200;
  binding.can->can_id = encode_can_id(CanIdentifier{0x11, 1, 200});  // cosmic layout: bit 21 set
  const Status status = adapter->configure(std::span(&binding, 1));
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.error.find("another identifier layout"), std::string::npos) << status.error;
  binding.can->profile = CanProfile::famouso;
  binding.can->can_id = encode_famouso_id(FamousoIdentifier{0x11, false, 1, 200});
  EXPECT_TRUE(adapter->configure(std::span(&binding, 1)).ok);
}

TEST(CanAdapterWithoutBus, ANonCanInterfaceIsReported) {
  NullLogger log;
  NullSink sink;
  auto adapter = make_can_adapter(can_segment("lo"), GatewayIdentity{1, "gw"}, log);
  ASSERT_TRUE(adapter->start(sink).ok);
  EXPECT_EQ(adapter->health().detail, "interface lo is not a CAN interface");
  adapter->stop();
}

}  // namespace
}  // namespace cosmic

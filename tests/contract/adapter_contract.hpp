// The contract every SegmentAdapter keeps (cosmic/segment_adapter.hpp: the lifecycle and
// configure()), as one typed GoogleTest suite that each transport's test program instantiates with
// a target of its own: memory (tests/runtime), CAN (in the VM), DDS and LCM (in a network
// namespace). The same cases, the same answers: only how a transport is made and which of its
// bindings collide differ.
//
// A target provides:
//   static constexpr const char* kName;                    // "memory", "can", "dds", "lcm"
//   std::unique_ptr<SegmentAdapter> make();                // a fresh adapter, not started
//   ChannelBinding binding(ChannelId, std::string name, HopRole);  // one the transport carries
//   // Two bindings of two channels the transport cannot carry side by side (they collide in its
//   // own namespace: topic, LCM channel, etag, ...): the second is refused, for a reason that
//   // contains collision_reason().
//   std::pair<ChannelBinding, ChannelBinding> colliding(ChannelId first, ChannelId second);
//   std::string collision_reason();
// Whether a channel is carried is asked the way the router asks: send() answers sent for a
// channel bound here as subscriber, failed for one that is not.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/log.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::contract {

// A binding as a transport without a plan of its own (memory, DDS, LCM) is given it.
inline ChannelBinding plain_binding(ChannelId id, const std::string& name, HopRole role) {
  ChannelBinding b;
  b.id = id;
  b.spec.name = name;
  b.spec.subject = 100 + id;
  b.role = role;
  return b;
}

// A segment of `type` named `name`, for the targets to complete.
inline SegmentSpec contract_segment(const std::string& name, SegmentType type) {
  SegmentSpec segment;
  segment.name = name;
  segment.type = type;
  return segment;
}

class QuietLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

class CountingSink final : public EventSink {
 public:
  void on_event(const InboundEvent&) override { events.fetch_add(1); }
  void on_problem(ChannelId, InboundProblem) override { problems.fetch_add(1); }
  std::atomic<int> events{0};
  std::atomic<int> problems{0};
};

// Names each instantiation by its transport: contract/AdapterContract/can.stop_forgets_...
struct TargetName {
  template <typename Target>
  static std::string GetName(int) {
    return Target::kName;
  }
};

template <typename Target>
class AdapterContract : public ::testing::Test {
 protected:
  void SetUp() override { adapter = target.make(); }
  void TearDown() override {
    if (adapter) adapter->stop();
  }

  SendStatus send_on(ChannelId channel) {
    const std::vector<std::uint8_t> payload{1, 2, 3, 4};
    OutboundEvent event;
    event.channel = channel;
    event.header.subject = 100 + channel;
    event.payload = payload;
    return adapter->send(event);
  }
  ChannelBinding sub(ChannelId id, const std::string& name) { return target.binding(id, name, HopRole::subscriber); }
  ChannelBinding pub(ChannelId id, const std::string& name) { return target.binding(id, name, HopRole::publisher); }
  void start() { ASSERT_TRUE(adapter->start(sink).ok); }
  Status configure(std::vector<ChannelBinding> bindings) { return adapter->configure(bindings); }
  static std::size_t refusals_of(const Status& status, ChannelId channel) {
    std::size_t n = 0;
    for (const auto& r : status.refused) n += r.channel == channel;
    return n;
  }

  Target target;
  CountingSink sink;
  std::unique_ptr<SegmentAdapter> adapter;
};

TYPED_TEST_SUITE_P(AdapterContract);

TYPED_TEST_P(AdapterContract, configure_before_start_fails_as_a_whole_and_carries_nothing) {
  const Status status = this->configure({this->sub(1, "speed")});
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.refused.empty()) << "not started is no refusal of one channel";
  EXPECT_NE(status.error.find("not started"), std::string::npos) << status.error;
  this->start();
  EXPECT_EQ(this->send_on(1), SendStatus::failed) << "a segment starts carrying nothing";
}

TYPED_TEST_P(AdapterContract, starting_twice_fails_and_changes_nothing) {
  this->start();
  ASSERT_TRUE(this->configure({this->sub(1, "speed")}).ok);
  CountingSink other;
  const Status again = this->adapter->start(other);
  EXPECT_FALSE(again.ok);
  EXPECT_NE(again.error.find("already started"), std::string::npos) << again.error;
  EXPECT_EQ(this->adapter->health().state, SegmentHealth::up) << this->adapter->health().detail;
  EXPECT_EQ(this->send_on(1), SendStatus::sent);
}

TYPED_TEST_P(AdapterContract, carries_what_it_is_given_in_its_roles) {
  this->start();
  const Status status = this->configure({this->sub(1, "speed"), this->pub(2, "distance")});
  ASSERT_TRUE(status.ok) << status.error;
  EXPECT_TRUE(status.refused.empty());
  EXPECT_EQ(this->send_on(1), SendStatus::sent);
  EXPECT_EQ(this->send_on(2), SendStatus::failed) << "bound as publisher only: the gateway does not send it here";
  EXPECT_EQ(this->send_on(7), SendStatus::failed) << "never bound";
  EXPECT_GE(this->adapter->statistics().sent, 1u);
}

TYPED_TEST_P(AdapterContract, binding_without_id_or_name_is_refused_and_the_rest_carried) {
  this->start();
  ChannelBinding nameless = this->sub(3, "nameless");
  nameless.spec.name.clear();
  ChannelBinding no_id = this->sub(kNoChannel, "no-id");
  const Status status = this->configure({this->sub(1, "speed"), nameless, no_id});
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 2u) << status.error;
  EXPECT_EQ(this->refusals_of(status, 3), 1u);
  EXPECT_EQ(this->refusals_of(status, kNoChannel), 1u);
  EXPECT_NE(status.error.find("no channel id or name"), std::string::npos) << status.error;
  EXPECT_EQ(this->send_on(1), SendStatus::sent);
  EXPECT_EQ(this->send_on(3), SendStatus::failed);
}

TYPED_TEST_P(AdapterContract, channel_bound_twice_in_one_role_is_refused_once_and_carried_in_no_role) {
  this->start();
  ASSERT_TRUE(this->configure({this->sub(1, "speed"), this->sub(2, "torque")}).ok);
  ASSERT_EQ(this->send_on(1), SendStatus::sent);
  const Status status =
      this->configure({this->sub(1, "speed"), this->pub(1, "speed"), this->sub(1, "speed"), this->sub(2, "torque")});
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 1u) << status.error;
  EXPECT_EQ(status.refused[0].channel, 1u);
  EXPECT_NE(status.error.find("channel speed: bound twice as subscriber"), std::string::npos) << status.error;
  EXPECT_EQ(this->send_on(1), SendStatus::failed) << "a refused channel is not carried, though it was before";
  EXPECT_EQ(this->send_on(2), SendStatus::sent);
}

TYPED_TEST_P(AdapterContract, transport_refusal_names_the_channel_and_the_rest_is_carried) {
  this->start();
  auto [first, second] = this->target.colliding(4, 5);
  const Status status = this->configure({this->sub(1, "speed"), first, second});
  EXPECT_FALSE(status.ok);
  ASSERT_EQ(status.refused.size(), 1u) << status.error;
  EXPECT_EQ(status.refused[0].channel, 5u);
  EXPECT_NE(status.refused[0].reason.find(this->target.collision_reason()), std::string::npos)
      << status.refused[0].reason;
  EXPECT_EQ(status.error.rfind("channel " + second.spec.name + ": ", 0), 0u) << status.error;
  EXPECT_EQ(this->send_on(1), SendStatus::sent);
}

TYPED_TEST_P(AdapterContract, a_channel_left_out_is_no_longer_carried) {
  this->start();
  ASSERT_TRUE(this->configure({this->sub(1, "speed"), this->sub(2, "torque")}).ok);
  ASSERT_EQ(this->send_on(1), SendStatus::sent);
  ASSERT_TRUE(this->configure({this->sub(2, "torque")}).ok);
  EXPECT_EQ(this->send_on(1), SendStatus::failed);
  EXPECT_EQ(this->send_on(2), SendStatus::sent);
  ASSERT_TRUE(this->configure({}).ok);
  EXPECT_EQ(this->send_on(2), SendStatus::failed);
}

TYPED_TEST_P(AdapterContract, stop_forgets_the_bindings_and_a_new_start_carries_nothing) {
  this->start();
  ASSERT_TRUE(this->configure({this->sub(1, "speed")}).ok);
  this->adapter->stop();
  EXPECT_EQ(this->adapter->health().state, SegmentHealth::down);
  EXPECT_EQ(this->send_on(1), SendStatus::failed);
  const Status stopped = this->configure({this->sub(1, "speed")});
  EXPECT_FALSE(stopped.ok);
  EXPECT_TRUE(stopped.refused.empty());
  this->adapter->stop();  // stopping a stopped segment does nothing
  this->start();
  EXPECT_EQ(this->send_on(1), SendStatus::failed);
  ASSERT_TRUE(this->configure({this->sub(1, "speed")}).ok);
  EXPECT_EQ(this->send_on(1), SendStatus::sent);
}

REGISTER_TYPED_TEST_SUITE_P(AdapterContract, configure_before_start_fails_as_a_whole_and_carries_nothing,
                            starting_twice_fails_and_changes_nothing, carries_what_it_is_given_in_its_roles,
                            binding_without_id_or_name_is_refused_and_the_rest_carried,
                            channel_bound_twice_in_one_role_is_refused_once_and_carried_in_no_role,
                            transport_refusal_names_the_channel_and_the_rest_is_carried,
                            a_channel_left_out_is_no_longer_carried,
                            stop_forgets_the_bindings_and_a_new_start_carries_nothing);

}  // namespace cosmic::contract

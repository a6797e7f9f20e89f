// An ingress thread that carries one class alone sends an event to an idle egress lane's
// transport itself (EgressLane::push_or_send, issue 39): the lane's thread is not woken. These
// tests run the router with its lane threads and a transport that records which thread sent each
// event and can hold a send, so every hand-over between the two senders is seen.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/syscall.h>
#include <unistd.h>

#include "cosmic/router.hpp"

namespace cosmic {
namespace {

constexpr std::uint64_t kDirectSendSelf = 0xBBBB;
constexpr auto kDirectSendPatience = std::chrono::seconds(20);

// The router's clock in these tests: it moves only when a test or a send moves it.
std::atomic<std::int64_t> fake_now_ns{1'000'000'000};
Nanos fake_now() { return Nanos(fake_now_ns.load()); }

// Records each send with its thread; a closed gate holds every send until it opens.
class RecordingTransport final : public SegmentAdapter {
 public:
  struct Sent {
    std::uint8_t first_byte = 0;
    std::thread::id thread;
  };

  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent& event) override {
    std::unique_lock lock(mutex_);
    ++entered_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return gate_open_; });
    sent_.push_back({event.payload.empty() ? std::uint8_t{0} : event.payload[0], std::this_thread::get_id()});
    fake_now_ns += send_cost_ns.load();
    changed_.notify_all();
    return SendStatus::sent;
  }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override { return {}; }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override {}

  std::atomic<std::int64_t> send_cost_ns{0};  // how far each send moves the fake clock

  void close_gate() {
    std::lock_guard lock(mutex_);
    gate_open_ = false;
  }
  void open_gate() {
    std::lock_guard lock(mutex_);
    gate_open_ = true;
    changed_.notify_all();
  }
  // Until `n` sends have begun (some may wait at the gate).
  bool wait_entered(std::size_t n) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDirectSendPatience, [&] { return entered_ >= n; });
  }
  bool wait_sent(std::size_t n) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDirectSendPatience, [&] { return sent_.size() >= n; });
  }
  std::vector<Sent> sent() const {
    std::lock_guard lock(mutex_);
    return sent_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool gate_open_ = true;
  std::size_t entered_ = 0;
  std::vector<Sent> sent_;
};

ChannelSpec nrt_channel(const std::string& name) {
  ChannelSpec c;
  c.name = name;
  c.subject = std::hash<std::string>{}(name);
  c.cls = ChannelClass::nrt;
  c.publishers = {"in"};
  c.subscribers = {"out"};
  return c;
}

class DirectSendTest : public ::testing::Test {
 protected:
  // Segment 0 publishes; segment 1 subscribes, and with `fanout` 2 segment 2 too. `both_ways`: segment 1
  // publishes the channel too.
  void start(std::uint32_t fanout = 1, bool both_ways = false) {
    RouterLimits limits;
    limits.threaded = true;
    router = std::make_unique<Router>(GatewayIdentity{kDirectSendSelf, "test"}, 3, limits, fake_now);
    router->set_segment(0, "in", &in);
    router->set_segment(1, "out", &out);
    router->set_segment(2, "also", &also);
    // "also" first: "out" is the last hop.
    std::vector<std::size_t> subscribers{1};
    if (fanout > 1) subscribers.insert(subscribers.begin(), 2);
    std::vector<Route> routes;
    std::vector<std::size_t> publishers{0};
    if (both_ways) publishers.push_back(1);
    routes.push_back(Route{1, nrt_channel("a"), publishers, subscribers, Nanos(0)});
    router->apply(std::move(routes));
  }

  void TearDown() override {
    if (router) router->stop();
  }

  // As an adapter's receive thread delivers it; `receiver`: InboundEvent::receiver_class.
  void deliver(std::uint8_t tag, std::optional<ChannelClass> receiver) {
    const std::vector<std::uint8_t> payload{tag};
    InboundEvent event{1, EventHeader{}, payload, fake_now()};
    event.receiver_class = receiver;
    router->inbox(0).on_event(event);
  }

  RecordingTransport in;
  RecordingTransport out;
  RecordingTransport also;
  std::unique_ptr<Router> router;
};

TEST_F(DirectSendTest, AThreadOfTheChannelsClassSendsToAnIdleLaneItself) {
  start();
  deliver(1, ChannelClass::nrt);
  // Sent before on_event returned, on this thread: no lane thread was involved.
  const auto sent = out.sent();
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].first_byte, 1);
  EXPECT_EQ(sent[0].thread, std::this_thread::get_id());
  EXPECT_EQ(router->queued(), 0u);
}

TEST_F(DirectSendTest, AThreadThatMayCarryAnotherClassLeavesTheSendToTheLane) {
  start();
  deliver(1, std::nullopt);       // CAN, LCM: one receive thread for every class
  deliver(2, ChannelClass::hrt);  // a thread of another class
  ASSERT_TRUE(out.wait_sent(2));
  for (const auto& s : out.sent()) EXPECT_NE(s.thread, std::this_thread::get_id());
}

// Events queued while an ingress thread sends go out after its event, on the lane's thread.
TEST_F(DirectSendTest, WhatQueuesBehindADirectSendFollowsItInOrder) {
  start();
  out.close_gate();
  std::thread receiver([&] { deliver(1, ChannelClass::nrt); });
  ASSERT_TRUE(out.wait_entered(1));
  deliver(2, ChannelClass::nrt);  // the lane is busy: queued, not sent here
  deliver(3, std::nullopt);
  EXPECT_EQ(router->queued(), 3u) << "the send in progress counts as queued (the watchdog's measure)";
  out.open_gate();
  receiver.join();
  ASSERT_TRUE(out.wait_sent(3));
  const auto sent = out.sent();
  ASSERT_EQ(sent.size(), 3u);
  EXPECT_EQ(sent[0].first_byte, 1);
  EXPECT_EQ(sent[1].first_byte, 2);
  EXPECT_EQ(sent[2].first_byte, 3);
  EXPECT_NE(sent[1].thread, std::this_thread::get_id());
  EXPECT_EQ(sent[1].thread, sent[2].thread) << "both went to the lane's thread";
}

// While the lane's thread is in a send, an ingress thread queues behind it instead of sending
// beside it (one sender per lane: order, and the transport's one thread per class).
TEST_F(DirectSendTest, ABusyLaneThreadKeepsTheSendsToItself) {
  start();
  deliver(1, std::nullopt);
  ASSERT_TRUE(out.wait_sent(1));
  out.close_gate();
  deliver(2, std::nullopt);
  ASSERT_TRUE(out.wait_entered(2));  // the lane's thread holds event 2 at the gate
  deliver(3, ChannelClass::nrt);
  EXPECT_EQ(out.sent().size(), 1u) << "event 3 must not overtake event 2";
  out.open_gate();
  ASSERT_TRUE(out.wait_sent(3));
  const auto sent = out.sent();
  EXPECT_EQ(sent[1].first_byte, 2);
  EXPECT_EQ(sent[2].first_byte, 3);
  EXPECT_NE(sent[2].thread, std::this_thread::get_id());
}

// With two subscriber segments the first hop's lane sends on its own thread and the last hop
// is sent here: no hop waits for the other's send.
TEST_F(DirectSendTest, OnlyTheLastHopIsSentHere) {
  start(2);
  also.close_gate();
  deliver(1, ChannelClass::nrt);  // returns although "also" holds its send: it is not this thread's
  ASSERT_EQ(also.sent().size(), 0u);
  ASSERT_TRUE(also.wait_entered(1));
  also.open_gate();
  ASSERT_TRUE(also.wait_sent(1));
  ASSERT_EQ(out.sent().size(), 1u);
  EXPECT_EQ(out.sent()[0].thread, std::this_thread::get_id()) << "out is the route's last hop";
  EXPECT_NE(also.sent()[0].thread, std::this_thread::get_id());
}

// The gateway's own reader of the channel on the hop may be handed the event within the send
// (Fast DDS's in-process delivery): such a send never runs on a receive thread.
TEST_F(DirectSendTest, AHopWhereTheGatewayAlsoReceivesTheChannelIsLeftToItsLane) {
  start(1, true);
  deliver(1, ChannelClass::nrt);
  ASSERT_TRUE(out.wait_sent(1));
  EXPECT_NE(out.sent()[0].thread, std::this_thread::get_id());
}

// A lane whose sends take much of the time hands every event to its own thread, so that the
// ingress thread goes back to receiving (two threads on two CPUs); once sending is light again,
// ingress threads send for themselves again.
TEST_F(DirectSendTest, ALaneBusySendingTakesTheSendsAwayFromTheReceiveThreadUntilItIsIdleAgain) {
  start();
  out.send_cost_ns = 1'000'000;  // back-to-back sends of 1 ms: the lane sends all the time
  std::uint8_t tag = 0;
  std::size_t direct = 0;
  bool handed_over = false;
  for (int i = 0; i < 100 && !handed_over; ++i) {
    deliver(++tag, ChannelClass::nrt);
    ASSERT_TRUE(out.wait_sent(tag));
    handed_over = out.sent().back().thread != std::this_thread::get_id();
    if (!handed_over) ++direct;
  }
  EXPECT_TRUE(handed_over) << "the receive thread kept sending all the time";
  EXPECT_GE(direct, 5u) << "a window of the duty is several sends long";
  // Light sending: 0 ms per send, 1 ms apart.
  out.send_cost_ns = 0;
  bool direct_again = false;
  for (int i = 0; i < 100 && !direct_again; ++i) {
    fake_now_ns += 1'000'000;
    deliver(++tag, ChannelClass::nrt);
    ASSERT_TRUE(out.wait_sent(tag));
    direct_again = out.sent().back().thread == std::this_thread::get_id();
  }
  EXPECT_TRUE(direct_again) << "the lane stayed loaded after its sends became light";
}

bool sleeping(pid_t tid) {
  std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'S';
}

// Taking a segment's adapter away waits for an ingress thread's send to it: the caller may free
// the adapter once set_segment(..., nullptr) returns.
TEST_F(DirectSendTest, TakingTheAdapterAwayWaitsForASendInProgress) {
  start();
  out.close_gate();
  std::thread receiver([&] { deliver(1, ChannelClass::nrt); });
  ASSERT_TRUE(out.wait_entered(1));
  std::atomic<pid_t> remover_tid{0};
  std::atomic<bool> removed{false};
  std::thread remover([&] {
    remover_tid = static_cast<pid_t>(::syscall(SYS_gettid));
    router->set_segment(1, "out", nullptr);
    removed = true;
  });
  // Until the remover sleeps (waiting for the send), or returned early (the failure).
  const auto deadline = std::chrono::steady_clock::now() + kDirectSendPatience;
  while ((remover_tid == 0 || !sleeping(remover_tid)) && !removed && std::chrono::steady_clock::now() < deadline)
    std::this_thread::yield();
  EXPECT_FALSE(removed) << "set_segment returned while a send to the adapter was in progress";
  out.open_gate();
  receiver.join();
  remover.join();
  EXPECT_TRUE(removed);
  EXPECT_EQ(out.sent().size(), 1u);
  deliver(2, ChannelClass::nrt);  // no adapter now: dropped, never sent to the old one
  EXPECT_EQ(out.sent().size(), 1u);
}

}  // namespace
}  // namespace cosmic

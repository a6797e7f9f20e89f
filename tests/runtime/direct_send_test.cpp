// An ingress thread that carries one class alone sends an event to an idle egress lane's
// transport itself (EgressLane::push_or_send, issue 39): the lane's thread is not woken. These
// tests run the router with its lane threads and a transport that records which thread sent each
// event and can hold a send, so every hand-over between the two senders is seen.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
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
    bool watched = false;  // the watched flag (watch()) was set when this send ended
  };

  Status start(EventSink&) override { return Status::success(); }
  Status configure(std::span<const ChannelBinding>) override { return Status::success(); }
  SendStatus send(const OutboundEvent& event) override {
    std::unique_lock lock(mutex_);
    ++entered_;
    changed_.notify_all();
    // A send held for ever would hang the test instead of failing it.
    if (!changed_.wait_for(lock, kDirectSendPatience, [&] { return gate_open_; }))
      ADD_FAILURE() << "a send waited at the closed gate for " << kDirectSendPatience.count() << " s";
    sent_.push_back({event.payload.empty() ? std::uint8_t{0} : event.payload[0], std::this_thread::get_id(),
                     watched_ != nullptr && watched_->load()});
    fake_now_ns += send_cost_ns.load();
    changed_.notify_all();
    return SendStatus::sent;
  }
  HealthReport health() const override { return {}; }
  AdapterStatistics statistics() const override { return {}; }
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }
  void stop() override {}
  bool batches_sends() const override { return batches; }
  bool batches = false;  // as LCM and CAN, which hand what queued over in one sendmmsg

  std::atomic<std::int64_t> send_cost_ns{0};  // how far each send moves the fake clock

  void watch(const std::atomic<bool>* flag) {
    std::lock_guard lock(mutex_);
    watched_ = flag;
  }

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
  const std::atomic<bool>* watched_ = nullptr;
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
    routes.push_back(Route{2, nrt_channel("b"), {0}, {2}, Nanos(0)});  // channel b: to "also" alone
    router->apply(std::move(routes));
  }

  // A second of the fake clock between tests: a send duty an earlier test left loaded (this
  // thread's own is thread_local) is judged over it, and loaded no longer.
  void SetUp() override { fake_now_ns += 1'000'000'000; }

  void TearDown() override {
    if (router) router->stop();
  }

  // As an adapter's receive thread delivers it; `receiver`: InboundEvent::receiver_class.
  void deliver(std::uint8_t tag, std::optional<ChannelClass> receiver, ChannelId channel = 1) {
    const std::vector<std::uint8_t> payload{tag};
    InboundEvent event{channel, EventHeader{}, payload, fake_now()};
    event.receiver_class = receiver;
    router->inbox(0).on_event(event);
  }

  RecordingTransport in;
  RecordingTransport out;
  RecordingTransport also;
  std::unique_ptr<Router> router;
};

bool sleeping(pid_t tid) {
  std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
  std::string line;
  std::getline(stat, line);
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'S';
}

// The tid of this process's thread of that name, or 0.
pid_t thread_id_named(const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(task.path() / "comm");
    std::string line;
    if (std::getline(comm, line) && line == name) return static_cast<pid_t>(std::stoi(task.path().filename()));
  }
  return 0;
}

bool wait_until_sleeping(const std::string& thread) {
  const auto deadline = std::chrono::steady_clock::now() + kDirectSendPatience;
  for (;;) {
    const pid_t tid = thread_id_named(thread);
    if (tid != 0 && sleeping(tid)) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::yield();
  }
}

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

// Each on an idle lane (a fresh router): only the class check keeps the send from this thread.
TEST_F(DirectSendTest, AThreadThatMayCarryEveryClassLeavesTheSendToTheLane) {
  start();
  deliver(1, std::nullopt);  // CAN, LCM: one receive thread for every class
  ASSERT_TRUE(out.wait_sent(1));
  EXPECT_NE(out.sent()[0].thread, std::this_thread::get_id());
}

// An adapter that batches sends is left to its lane's thread, which hands it what queued at once.
TEST_F(DirectSendTest, AnAdapterThatBatchesSendsIsLeftToItsLane) {
  out.batches = true;
  start();
  deliver(1, ChannelClass::nrt);
  ASSERT_TRUE(out.wait_sent(1));
  EXPECT_NE(out.sent()[0].thread, std::this_thread::get_id());
}

TEST_F(DirectSendTest, AThreadOfAnotherClassLeavesTheSendToTheLane) {
  start();
  deliver(1, ChannelClass::hrt);
  ASSERT_TRUE(out.wait_sent(1));
  EXPECT_NE(out.sent()[0].thread, std::this_thread::get_id());
}

// Events queued while an ingress thread sends go out after its event, on the lane's thread.
TEST_F(DirectSendTest, WhatQueuesBehindADirectSendFollowsItInOrder) {
  start();
  out.close_gate();
  std::thread receiver([&] { deliver(1, ChannelClass::nrt); });
  const std::thread::id receiver_id = receiver.get_id();
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
  EXPECT_EQ(sent[0].thread, receiver_id);
  EXPECT_NE(sent[1].thread, receiver_id) << "the direct sender hands what queued to the lane";
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
  out.send_cost_ns = 150'000;  // back to back, each below the residence bound: the lane sends all the time
  std::uint8_t tag = 0;
  std::size_t direct = 0;
  bool handed_over = false;
  for (int i = 0; i < 200 && !handed_over; ++i) {
    deliver(++tag, ChannelClass::nrt);
    ASSERT_TRUE(out.wait_sent(tag));
    handed_over = out.sent().back().thread != std::this_thread::get_id();
    if (!handed_over) ++direct;
  }
  EXPECT_TRUE(handed_over) << "the receive thread kept sending all the time";
  EXPECT_GE(direct, 60u) << "a window of the duty (10 ms) is about 67 of these sends";
  // Light sending: none of the time, 1 ms apart. The clock moves only while the lane's thread
  // sleeps, so that no send of its measures the test's step.
  out.send_cost_ns = 0;
  bool direct_again = false;
  for (int i = 0; i < 100 && !direct_again; ++i) {
    ASSERT_TRUE(wait_until_sleeping("nrt:out"));
    fake_now_ns += 1'000'000;
    deliver(++tag, ChannelClass::nrt);
    ASSERT_TRUE(out.wait_sent(tag));
    direct_again = out.sent().back().thread == std::this_thread::get_id();
  }
  EXPECT_TRUE(direct_again) << "the lane stayed loaded after its sends became light";
}

// One send that takes long (a congested network, a blocking transport) ends the receive thread's
// sending for this lane at once: the next events go to the lane's thread.
TEST_F(DirectSendTest, OneSlowSendHandsTheLaneBackToItsThread) {
  start();
  out.send_cost_ns = 1'000'000;  // the residence bound (RouterLimits' default)
  deliver(1, ChannelClass::nrt);
  ASSERT_EQ(out.sent().size(), 1u);
  EXPECT_EQ(out.sent()[0].thread, std::this_thread::get_id());
  out.send_cost_ns = 0;
  deliver(2, ChannelClass::nrt);
  ASSERT_TRUE(out.wait_sent(2));
  EXPECT_NE(out.sent()[1].thread, std::this_thread::get_id());
}

// A receive thread that feeds two lanes, each busy sending less than half the time, sends nearly
// all the time: it is judged by the sum, and the lanes' threads take the sends over.
TEST_F(DirectSendTest, AReceiveThreadIsJudgedByAllTheSendsItMakes) {
  start();
  out.send_cost_ns = 150'000;  // below the residence bound
  also.send_cost_ns = 150'000;
  std::uint8_t tag = 0;
  bool handed_over = false;
  for (int i = 0; i < 200 && !handed_over; ++i) {
    fake_now_ns += 17'000;
    const bool to_out = i % 2 == 0;
    deliver(++tag, ChannelClass::nrt, to_out ? 1 : 2);
    RecordingTransport& to = to_out ? out : also;
    ASSERT_TRUE(to.wait_sent(static_cast<std::size_t>(i / 2 + 1)));
    handed_over = to.sent().back().thread != std::this_thread::get_id();
  }
  EXPECT_TRUE(handed_over) << "each lane sends 45% of the time, this thread 90%: it must hand over";
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
  out.watch(&removed);
  std::thread remover([&] {
    remover_tid = static_cast<pid_t>(::syscall(SYS_gettid));
    router->set_segment(1, "out", nullptr);
    removed = true;
  });
  // Until the remover sleeps in the NRT lane (its HRT and SRT lanes' threads are gone, the NRT
  // lane's thread not yet: deactivate() waits for the send before it joins that thread), or
  // returned early (the failure).
  const auto in_nrt_lane = [&] {
    return remover_tid != 0 && thread_id_named("hrt:out") == 0 && thread_id_named("srt:out") == 0 &&
           thread_id_named("nrt:out") != 0 && sleeping(remover_tid);
  };
  const auto deadline = std::chrono::steady_clock::now() + kDirectSendPatience;
  while (!in_nrt_lane() && !removed && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  EXPECT_FALSE(removed) << "set_segment returned while a send to the adapter was in progress";
  out.open_gate();
  receiver.join();
  remover.join();
  EXPECT_TRUE(removed);
  ASSERT_EQ(out.sent().size(), 1u);
  EXPECT_FALSE(out.sent()[0].watched) << "set_segment had returned when the send ended";
  deliver(2, ChannelClass::nrt);  // no adapter now: dropped, never sent to the old one
  EXPECT_EQ(out.sent().size(), 1u);
}

}  // namespace
}  // namespace cosmic

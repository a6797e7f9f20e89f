// The LCM adapter's own transport (lib/adapters/lcm/src/lcm_sockets.cpp) against liblcm in
// another process (cosmic-lcm-peer): messages too large for one datagram cross in LCM's fragments
// both ways, the kernel's drops on a full receive buffer are counted, memq:// runs with no socket.
#include <condition_variable>
#include <mutex>

#include <nlohmann/json.hpp>

#include "lcm_adapter_fixture.hpp"

namespace cosmic::lcm_test {
namespace {

// 200,000 bytes: four fragments of liblcm's 65,487 bytes.
constexpr std::size_t kLarge = 200'000;

TEST_F(LcmAdapterTest, MessagesBeyondOneDatagramCrossInFragmentsBothWays) {
  const int port = 7720;
  segment_.max_message_size = 1u << 20;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(1, "BIG_IN", HopRole::publisher, LcmEncoding::raw, 3),
                                             binding(2, "BIG_OUT", HopRole::subscriber)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  // liblcm fragments, we reassemble.
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "BIG_IN", "--raw", "--count", "3", "--size",
             std::to_string(kLarge), "--rate", "50"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(1, 3)) << sink_.count(1) << " of 3 large messages";
  const auto in = sink_.events(1);
  for (std::size_t i = 0; i < in.size(); ++i)
    EXPECT_EQ(in[i].payload, peer_pattern(i + 1, kLarge)) << "message " << i + 1;

  // We fragment, liblcm reassembles.
  Child sub({peer(), "sub", "--url", url_for(port), "--channel", "BIG_OUT", "--count", "3", "--timeout", "10"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();
  // One at a time: the subscriber's default socket buffer holds about one such message.
  for (std::uint32_t k = 1; k <= 3; ++k) {
    ASSERT_EQ(adapter->send(outbound(2, own_pattern(k, kLarge + k), k, 0xB16, self_.id)), SendStatus::sent);
    ASSERT_TRUE(sub.wait_stdout_lines(k)) << sub.stderr_text();
  }
  ASSERT_EQ(sub.wait_exit(), std::optional<int>(0)) << sub.stderr_text();
  const auto lines = sub.stdout_lines();
  ASSERT_EQ(lines.size(), 3u);
  for (std::uint32_t k = 1; k <= 3; ++k) {
    const auto j = nlohmann::json::parse(lines[k - 1]);
    EXPECT_EQ(j["sequence"].get<std::uint32_t>(), k);
    EXPECT_EQ(j["subject"].get<std::uint64_t>(), 0xB16u);
    EXPECT_EQ(j["payload"].get<std::string>(), hex(own_pattern(k, kLarge + k)));
  }
  EXPECT_EQ(adapter->statistics().receive_errors, 0u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, AMessageBeyondTheSegmentsLimitIsNotReassembled) {
  const int port = 7721;
  segment_.max_message_size = 100'000;
  auto adapter = make(port);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{binding(1, "BIG_IN", HopRole::publisher, LcmEncoding::raw, 3)}).ok);
  Child big({peer(), "pub", "--url", url_for(port), "--channel", "BIG_IN", "--raw", "--count", "2", "--size",
             std::to_string(kLarge)});
  ASSERT_EQ(big.wait_exit(), std::optional<int>(0)) << big.stderr_text();
  // A small one after them arrives alone: the large ones were refused, not delivered late.
  Child small({peer(), "pub", "--url", url_for(port), "--channel", "BIG_IN", "--raw", "--count", "1", "--size", "8"});
  ASSERT_EQ(small.wait_exit(), std::optional<int>(0)) << small.stderr_text();
  ASSERT_TRUE(sink_.wait_events(1, 1));
  const auto in = sink_.events(1);
  ASSERT_EQ(in.size(), 1u);
  EXPECT_EQ(in[0].payload, peer_pattern(1, 8));
  // Each of their four fragments was refused and counted (none held: they never fit).
  EXPECT_EQ(adapter->statistics().receive_errors, 8u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, FragmentsOfAChannelNotReceivedHereAreSkippedWhole) {
  const int port = 7724;
  segment_.max_message_size = 1u << 20;
  auto adapter = make(port);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{binding(1, "BIG_IN", HopRole::publisher, LcmEncoding::raw, 3)}).ok);
  // Another program's large messages on a channel this segment does not carry: fragment 0 names
  // it, the three after it carry no name and must not be held (nor counted lost).
  Child other({peer(), "pub", "--url", url_for(port), "--channel", "NOT_OURS", "--raw", "--count", "3", "--size",
               std::to_string(kLarge), "--rate", "50"});
  ASSERT_EQ(other.wait_exit(), std::optional<int>(0)) << other.stderr_text();
  Child ours({peer(), "pub", "--url", url_for(port), "--channel", "BIG_IN", "--raw", "--count", "1", "--size",
              std::to_string(kLarge)});
  ASSERT_EQ(ours.wait_exit(), std::optional<int>(0)) << ours.stderr_text();
  ASSERT_TRUE(sink_.wait_events(1, 1));
  EXPECT_EQ(sink_.events(1).at(0).payload, peer_pattern(1, kLarge));
  EXPECT_EQ(adapter->statistics().receive_errors, 0u);
  EXPECT_EQ(adapter->statistics().received, 1u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, ABatchGoesOutInOrderWithEachEventsOwnStatus) {
  const int port = 7723;
  segment_.max_message_size = 1u << 20;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(1, "BATCH_ENV", HopRole::subscriber),
                                             binding(2, "BATCH_RAW", HopRole::subscriber, LcmEncoding::raw, 4)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);
  ASSERT_TRUE(adapter->batches_sends());
  Child env({peer(), "sub", "--url", url_for(port), "--channel", "BATCH_ENV", "--count", "41", "--timeout", "10"});
  Child raw(
      {peer(), "sub", "--url", url_for(port), "--channel", "BATCH_RAW", "--raw", "--count", "4", "--timeout", "10"});
  ASSERT_TRUE(env.wait_stderr("READY")) << env.stderr_text();
  ASSERT_TRUE(raw.wait_stderr("READY")) << raw.stderr_text();

  // More events than one sendmmsg takes (32), two channels, one event of a channel not bound
  // here, and one envelope that needs fragments (it goes alone, in its place).
  std::vector<Bytes> payloads;
  std::vector<OutboundEvent> events;
  payloads.reserve(46);
  for (std::uint32_t k = 1; k <= 41; ++k) {
    payloads.push_back(own_pattern(k, k == 20 ? 70'000 : 8 + k));
    events.push_back(outbound(1, payloads.back(), k, 0xBA7, self_.id));
    if (k % 10 == 5) {
      payloads.push_back(own_pattern(100 + k, 12));
      events.push_back(outbound(2, payloads.back()));
    }
    if (k == 33) {
      payloads.push_back(Bytes{9});
      events.push_back(outbound(9, payloads.back()));
    }
  }
  ASSERT_EQ(events.size(), 46u);
  std::vector<SendStatus> results(events.size(), SendStatus::failed);
  adapter->send_batch(events, results);
  for (std::size_t i = 0; i < events.size(); ++i)
    EXPECT_EQ(results[i], events[i].channel == 9 ? SendStatus::failed : SendStatus::sent) << "event " << i;

  ASSERT_EQ(env.wait_exit(), std::optional<int>(0)) << env.stderr_text();
  const auto lines = env.stdout_lines();
  ASSERT_EQ(lines.size(), 41u);
  for (std::uint32_t k = 1; k <= 41; ++k) {
    const auto j = nlohmann::json::parse(lines[k - 1]);
    EXPECT_EQ(j["sequence"].get<std::uint32_t>(), k);
    EXPECT_EQ(j["payload"].get<std::string>(), hex(own_pattern(k, k == 20 ? 70'000 : 8 + k)));
  }
  ASSERT_EQ(raw.wait_exit(), std::optional<int>(0)) << raw.stderr_text();
  const auto raw_lines = raw.stdout_lines();
  ASSERT_EQ(raw_lines.size(), 4u);
  for (std::size_t i = 0; i < raw_lines.size(); ++i)
    EXPECT_EQ(nlohmann::json::parse(raw_lines[i])["payload"].get<std::string>(),
              hex(own_pattern(100 + 5 + 10 * i, 12)));
  EXPECT_EQ(adapter->statistics().sent, 45u);
  EXPECT_EQ(adapter->statistics().send_errors, 1u);
  adapter->stop();
}

// Holds the receive thread inside on_event until released, so the socket's buffer fills.
class BlockingSink final : public EventSink {
 public:
  void on_event(const InboundEvent&) override {
    std::unique_lock lock(mutex_);
    ++events_;
    changed_.notify_all();
    changed_.wait(lock, [&] { return released_; });
  }
  void on_problem(ChannelId, InboundProblem) override {}
  bool wait_events(std::size_t n) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kWait, [&] { return events_ >= n; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t events_ = 0;
  bool released_ = false;
};

// `count` raw 64-byte messages on FLOOD from a peer; its exit status once it is done.
std::optional<int> publish_flood(int port, int count) {
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "FLOOD", "--raw", "--count", std::to_string(count),
             "--size", "64"});
  return pub.wait_exit();
}

TEST_F(LcmAdapterTest, DatagramsTheKernelDropsForAFullBufferAreCounted) {
  const int port = 7722;
  segment_.name = "lcm0";
  segment_.type = SegmentType::lcm;
  // The smallest buffer Linux grants: a few datagrams.
  segment_.lcm.url = url_for(port) + "&recv_buf_size=2048";
  auto adapter = make_lcm_adapter(segment_, self_, logger_);
  BlockingSink sink;
  ASSERT_TRUE(adapter->start(sink).ok);
  ASSERT_TRUE(adapter->configure(std::vector{binding(1, "FLOOD", HopRole::publisher, LcmEncoding::raw, 3)}).ok);
  ASSERT_EQ(publish_flood(port, 1), std::optional<int>(0));
  ASSERT_TRUE(sink.wait_events(1));  // the receive thread is held now
  ASSERT_EQ(publish_flood(port, 500), std::optional<int>(0));
  sink.release();
  // A datagram queued after the drops carries their count (SO_RXQ_OVFL).
  std::uint64_t drops = 0;
  ASSERT_TRUE(poll_until([&] {
    publish_flood(port, 1);
    drops = adapter->statistics().overflow_drops;
    return drops > 0;
  })) << "no drop counted; received "
      << adapter->statistics().received;
  const auto stats = adapter->statistics();
  EXPECT_LE(stats.received + stats.overflow_drops, 1u + 500u + 200u) << "more accounted for than were sent";
  EXPECT_GT(stats.received, 1u);
  adapter->stop();
}

// own_datagrams: drop with a real overflow at the same time: while the receive thread is held,
// the segment sends 300 datagrams of its own (dropped by its filter) and a peer floods a buffer of
// a few datagrams. The socket's drops are both; overflow_drops is exactly the flood's share, and
// own_datagrams_dropped the 300.
TEST_F(LcmAdapterTest, OwnDropsAndAFullBufferAreToldApart) {
  const int port = 7725;
  segment_.name = "lcm0";
  segment_.type = SegmentType::lcm;
  segment_.lcm.url = url_for(port) + "&recv_buf_size=2048";
  ASSERT_EQ(segment_.lcm.own_datagrams, LcmOwnDatagrams::drop);
  auto adapter = make_lcm_adapter(segment_, self_, logger_);
  BlockingSink sink;
  ASSERT_TRUE(adapter->start(sink).ok);
  ASSERT_TRUE(adapter
                  ->configure(std::vector{binding(1, "FLOOD", HopRole::publisher, LcmEncoding::raw, 3),
                                          binding(2, "MINE", HopRole::subscriber, LcmEncoding::raw, 4)})
                  .ok);
  ASSERT_EQ(publish_flood(port, 1), std::optional<int>(0));
  ASSERT_TRUE(sink.wait_events(1));  // the receive thread is held now
  for (std::uint32_t k = 1; k <= 300; ++k) ASSERT_EQ(adapter->send(outbound(2, own_pattern(k, 32))), SendStatus::sent);
  ASSERT_EQ(publish_flood(port, 500), std::optional<int>(0));
  sink.release();
  // A datagram queued after the drops carries their count: once one has been read, the segment's
  // figure is the socket's drops less our 300.
  std::uint64_t socket_drops = 0;
  ASSERT_TRUE(poll_until([&] {
    publish_flood(port, 1);
    socket_drops = udp_socket_drops(port);
    return socket_drops > 300 && adapter->statistics().overflow_drops == socket_drops - 300;
  })) << "socket drops "
      << socket_drops << ", overflow_drops " << adapter->statistics().overflow_drops;
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(300));
  adapter->stop();
}

TEST_F(LcmAdapterTest, AMemqSegmentRunsWithNoSocketAndReceivesNothing) {
  segment_.name = "viz";
  segment_.type = SegmentType::lcm;
  segment_.lcm.url = "memq://";
  auto adapter = make_lcm_adapter(segment_, self_, logger_);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{binding(1, "VIZ", HopRole::subscriber)}).ok);
  EXPECT_EQ(adapter->health().state, SegmentHealth::up);
  EXPECT_EQ(adapter->send(outbound(1, Bytes{1, 2, 3})), SendStatus::sent);
  EXPECT_EQ(adapter->send(outbound(9, Bytes{1})), SendStatus::failed);  // not bound
  EXPECT_EQ(adapter->statistics().sent, 1u);
  adapter->stop();
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  EXPECT_EQ(adapter->send(outbound(1, Bytes{1})), SendStatus::failed);  // stopped
}

}  // namespace
}  // namespace cosmic::lcm_test

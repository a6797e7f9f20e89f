// LCM segment adapter against real LCM peers in separate processes: cosmic-lcm-peer and the
// stock lcm-logger. Each test runs in its own network namespace (scripts/netns-run, multicast on
// loopback only) and uses its own multicast port. Tests wait on conditions, never on fixed sleeps.
// This file: health and bad URLs, envelopes to a native subscriber, raw messages from a native
// publisher and to lcm-logger, native bindings, restarts and own messages looped back.
// Reconfiguration while events flow, malformed envelopes, the channel name limit and the envelope
// decoder are in lcm_adapter_reconfig_test.cpp; the shared helpers in lcm_adapter_fixture.hpp.
#include <signal.h>
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/lcm_adapter.hpp"
#include "lcm_adapter_fixture.hpp"

namespace cosmic::lcm_test {
namespace {

// ---------------------------------------------------------------------------------------------

TEST_F(LcmAdapterTest, HealthAndBadUrl) {
  auto adapter = make(7700);
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  adapter->stop();  // stop before start is harmless

  segment_.lcm.url = "nosuchprovider://x";
  auto bad = make_lcm_adapter(segment_, self_, logger_);
  const std::vector<ChannelBinding> bindings{binding(1, "CH", HopRole::publisher)};
  const Status st = bad->start(sink_);
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.error.find("nosuchprovider://x"), std::string::npos) << st.error;
  EXPECT_EQ(bad->health().state, SegmentHealth::down);
  EXPECT_NE(bad->health().detail.find("bad LCM URL"), std::string::npos) << bad->health().detail;
  // A segment that did not start carries nothing (SegmentAdapter's lifecycle): the whole segment
  // fails to configure, naming no channel.
  const Status unstarted = bad->configure(bindings);
  EXPECT_FALSE(unstarted.ok);
  EXPECT_TRUE(unstarted.refused.empty());
  EXPECT_NE(unstarted.error.find("not started"), std::string::npos) << unstarted.error;
  EXPECT_EQ(bad->send(outbound(1, Bytes{1, 2})), SendStatus::failed);
  bad->stop();
  bad->stop();

  ASSERT_TRUE(adapter->start(sink_).ok);
  EXPECT_EQ(adapter->health().state, SegmentHealth::up);
  EXPECT_FALSE(adapter->start(sink_).ok);  // already started
  adapter->stop();
  adapter->stop();
  EXPECT_EQ(adapter->health().state, SegmentHealth::down);
}

TEST_F(LcmAdapterTest, PeerSubscriberTimesOutWithoutMessages) {
  Child sub({peer(), "sub", "--url", url_for(7701), "--channel", "NOBODY", "--count", "1", "--timeout", "0.3"});
  ASSERT_TRUE(sub.wait_stderr("READY"));
  const auto code = sub.wait_exit();
  ASSERT_TRUE(code.has_value());
  EXPECT_NE(*code, 0);
}

TEST_F(LcmAdapterTest, EnvelopeToNativeSubscriber) {
  const int port = 7702;
  constexpr int kCount = 40;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(7, "COSMIC_ENV", HopRole::subscriber)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  Child sub({peer(), "sub", "--url", url_for(port), "--channel", "COSMIC_ENV", "--count", std::to_string(kCount),
             "--timeout", "10"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();

  for (std::uint32_t k = 1; k <= kCount; ++k) {
    const Bytes payload = own_pattern(k, 8 + k);
    // Odd events originate here (the router stamped this gateway's id), even ones elsewhere. The
    // adapter sends the header as given, as the DDS adapter does.
    const std::uint64_t origin = (k % 2 == 1) ? self_.id : 777;
    ASSERT_EQ(adapter->send(outbound(7, payload, k, 0xC0FFEE, origin)), SendStatus::sent);
  }
  const auto code = sub.wait_exit();
  ASSERT_EQ(code, std::optional<int>(0)) << sub.stderr_text();
  const auto lines = sub.stdout_lines();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t k = 1; k <= kCount; ++k) {
    const auto j = nlohmann::json::parse(lines[k - 1]);
    EXPECT_EQ(j["channel"], "COSMIC_ENV");
    EXPECT_EQ(j["sequence"].get<std::uint32_t>(), k);
    EXPECT_EQ(j["subject"].get<std::uint64_t>(), 0xC0FFEEu);
    EXPECT_EQ(j["origin"].get<std::uint64_t>(), (k % 2 == 1) ? self_.id : 777u);
    EXPECT_EQ(j["hop_count"].get<int>(), 1);
    EXPECT_EQ(j["age_ns"].get<std::int64_t>(), 1000 * static_cast<std::int64_t>(k));
    EXPECT_EQ(j["created_ns"].get<std::int64_t>(), 123456789);
    EXPECT_EQ(j["payload"].get<std::string>(), hex(own_pattern(k, 8 + k)));
  }
  EXPECT_EQ(adapter->statistics().sent, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(adapter->statistics().send_errors, 0u);
  // Not bound for sending: refused.
  EXPECT_EQ(adapter->send(outbound(99, Bytes{1})), SendStatus::failed);
  adapter->stop();
}

TEST_F(LcmAdapterTest, RawFromNativePublisherKeepsBytes) {
  const int port = 7703;
  constexpr int kCount = 60;
  constexpr std::size_t kSize = 64;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(3, "NATIVE_POSE", HopRole::publisher, LcmEncoding::raw, 4242)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "NATIVE_POSE", "--raw", "--count",
             std::to_string(kCount), "--size", std::to_string(kSize), "--rate", "2000"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(3, kCount)) << sink_.count(3);

  const auto events = sink_.events(3);
  ASSERT_EQ(events.size(), static_cast<std::size_t>(kCount));
  for (std::size_t i = 0; i < events.size(); ++i) {
    const auto& e = events[i];
    EXPECT_EQ(e.payload, peer_pattern(i + 1, kSize)) << "message " << i + 1;
    EXPECT_EQ(e.header.subject, 4242u);
    EXPECT_EQ(e.header.origin, 0u);
    EXPECT_EQ(e.header.sequence, 0u);
    EXPECT_EQ(e.header.age_ns, 0);
    EXPECT_EQ(e.header.hop_count, 0);
  }
  EXPECT_EQ(adapter->statistics().received, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(sink_.problems(3, InboundProblem::own_echo), 0u);
  adapter->stop();
}

// A native binding (issue 19, item 5) names the LCM channel; the contents travel raw, and the router
// is told to guard loops by fingerprint (raw messages carry no origin).
TEST_F(LcmAdapterTest, ANativeBindingNamesTheLcmChannelAndCarriesTheContentsRaw) {
  const int port = 7711;
  auto adapter = make(port);
  ChannelBinding wheel = binding(9, "wheel", HopRole::publisher, LcmEncoding::envelope, 0x90);
  wheel.spec.native.push_back(NativeBinding{"lcm0", std::nullopt, "WHEEL_SPEED", std::nullopt});
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector<ChannelBinding>{wheel}).ok);
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "WHEEL_SPEED", "--raw", "--count", "5", "--size", "8",
             "--rate", "1000"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(9, 5)) << sink_.count(9);
  const auto events = sink_.events(9);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 8)) << "message " << i + 1;
    EXPECT_EQ(events[i].header.subject, 0x90u);
    EXPECT_TRUE(events[i].fingerprint_guard);
  }
  // Nothing is read on the channel's own name.
  Child other({peer(), "pub", "--url", url_for(port), "--channel", "wheel", "--raw", "--count", "3", "--size", "8"});
  ASSERT_EQ(other.wait_exit(), std::optional<int>(0)) << other.stderr_text();
  Child marker(
      {peer(), "pub", "--url", url_for(port), "--channel", "WHEEL_SPEED", "--raw", "--count", "1", "--size", "4"});
  ASSERT_EQ(marker.wait_exit(), std::optional<int>(0)) << marker.stderr_text();
  ASSERT_TRUE(sink_.wait_events(9, 6)) << sink_.count(9);
  EXPECT_EQ(sink_.count(9), 6u);  // the marker after the three on "wheel": those were never delivered
  adapter->stop();
}

TEST_F(LcmAdapterTest, RestartResubscribes) {
  const int port = 7709;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(4, "AGAIN", HopRole::publisher, LcmEncoding::raw, 1)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);
  adapter->stop();
  ASSERT_TRUE(adapter->start(sink_).ok);         // stop() forgot the channels: a new start carries none
  ASSERT_TRUE(adapter->configure(bindings).ok);  // until configured again, which joins the group
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "AGAIN", "--raw", "--count", "3", "--size", "4"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(4, 3));
  EXPECT_EQ(adapter->health().state, SegmentHealth::up);
  adapter.reset();  // the destructor stops
}

TEST_F(LcmAdapterTest, RawSendIsRecordedByLcmLogger) {
  const int port = 7704;
  const std::string url = url_for(port);
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(1, "RAW_SCAN", HopRole::subscriber, LcmEncoding::raw),
                                             binding(2, "COSMIC_PROBE", HopRole::subscriber, LcmEncoding::raw)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  char dir_template[] = "/tmp/cosmic-lcm-log-XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  struct RemoveDir {
    std::string path;
    ~RemoveDir() { std::filesystem::remove_all(path); }
  } remove_dir{dir_template};
  const std::string log_path = std::string(dir_template) + "/scan.lcmlog";

  Child logger({cosmic::build_paths::lcm_logger, "-q", "-f", "--flush-interval=10", "--lcm-url=" + url, log_path});
  // lcm-logger has no readiness signal: publish probes until one shows up in its file.
  const Bytes probe{0x50, 0x52, 0x4f, 0x42, 0x45};
  ASSERT_TRUE(poll_until([&] { return count_channel(read_lcm_log(log_path), "COSMIC_PROBE") > 0; }, kWait,
                         [&] { adapter->send(outbound(2, probe)); }))
      << logger.stderr_text();

  // Sizes from 1 byte to a fragmented 20 kB message.
  std::vector<Bytes> sent;
  const std::size_t sizes[] = {1, 8, 64, 200, 1400, 1500, 20000};
  for (std::uint32_t k = 1; k <= 35; ++k) sent.push_back(own_pattern(k, sizes[k % 7]));
  // One at a time, each once logged: a burst of 20 kB datagrams can overrun the logger's
  // receive buffers, which is LCM's business, not the adapter's. lcm-logger flushes its file
  // only when it writes an event, so probes keep nudging it until the message shows up.
  for (std::size_t i = 0; i < sent.size(); ++i) {
    ASSERT_EQ(adapter->send(outbound(1, sent[i])), SendStatus::sent);
    ASSERT_TRUE(poll_until([&] { return count_channel(read_lcm_log(log_path), "RAW_SCAN") > i; }, kWait,
                           [&] { adapter->send(outbound(2, probe)); }))
        << "message " << i << " not logged; " << logger.stderr_text();
  }
  logger.signal(SIGINT);
  ASSERT_TRUE(logger.wait_exit().has_value()) << logger.stderr_text();

  std::vector<Bytes> logged;
  for (const auto& e : read_lcm_log(log_path))
    if (e.channel == "RAW_SCAN") logged.push_back(e.data);
  EXPECT_EQ(logged, sent);
  adapter->stop();
}

TEST_F(LcmAdapterTest, OwnEnvelopesAreNotReceivedBack) {
  const int port = 7705;
  segment_.lcm.own_datagrams = LcmOwnDatagrams::cut;
  auto adapter = make(port);
  // The same channel received and sent on this segment: LCM loops our publications back.
  const std::vector<ChannelBinding> bindings{binding(5, "LOOPED", HopRole::publisher),
                                             binding(5, "LOOPED", HopRole::subscriber)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  // Ours go out (a native subscriber hears them: EnvelopeToNativeSubscriber) and loop back to our
  // own socket, whose filter (own_datagrams: cut) empties them in the kernel and the receive
  // thread skips them: the peer's, sent after, arrive alone.
  for (std::uint32_t k = 1; k <= 10; ++k)
    ASSERT_EQ(adapter->send(outbound(5, own_pattern(k, 16), k, 0, self_.id)), SendStatus::sent);

  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "LOOPED", "--count", "5", "--size", "16", "--origin",
             "5", "--subject", "9"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(5, 5));

  const auto events = sink_.events(5);
  ASSERT_EQ(events.size(), 5u);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].header.origin, 5u);
    EXPECT_EQ(events[i].header.subject, 9u);
    EXPECT_EQ(events[i].header.sequence, i + 1);
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 16));
  }
  EXPECT_EQ(sink_.problems(5, InboundProblem::own_echo), 0u);
  EXPECT_EQ(adapter->statistics().received, 5u);
  // Emptied by the filter, not dropped: the kernel counted no drop, and there is none to report.
  EXPECT_EQ(adapter->statistics().overflow_drops, 0u);
  EXPECT_EQ(adapter->statistics().receive_errors, 0u);
  EXPECT_EQ(udp_socket_drops(port), 0u);
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::nullopt);

  // Envelopes carrying this gateway's origin that it did not just publish (a loop through another
  // gateway, or a spoof) are delivered, for the router's ingress check to drop and count.
  Child spoof({peer(), "pub", "--url", url_for(port), "--channel", "LOOPED", "--count", "3", "--size", "16", "--origin",
               std::to_string(self_.id), "--subject", "9"});
  ASSERT_EQ(spoof.wait_exit(), std::optional<int>(0)) << spoof.stderr_text();
  ASSERT_TRUE(sink_.wait_events(5, 8));
  for (std::size_t i = 5; i < 8; ++i) EXPECT_EQ(sink_.events(5).at(i).header.origin, self_.id);
  EXPECT_EQ(sink_.problems(5, InboundProblem::own_echo), 0u);
  adapter->stop();
}

// own_datagrams: drop, the default. Ours never reach the receive socket's queue; the kernel
// counts each as a drop of that socket, and the segment's overflow count leaves them out: a burst
// of ours, short and in fragments, then the peer's, and overflow_drops stays 0, while
// own_datagrams_dropped names them, across a restart too.
TEST_F(LcmAdapterTest, DroppedOwnDatagramsAreNoOverflow) {
  const int port = 7708;
  ASSERT_EQ(segment_.lcm.own_datagrams, LcmOwnDatagrams::drop);
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(7, "LOOPED_DROP", HopRole::publisher, LcmEncoding::raw, 12),
                                             binding(7, "LOOPED_DROP", HopRole::subscriber, LcmEncoding::raw, 12)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);
  for (std::uint32_t k = 1; k <= 50; ++k) ASSERT_EQ(adapter->send(outbound(7, own_pattern(k, 24))), SendStatus::sent);
  ASSERT_EQ(adapter->send(outbound(7, own_pattern(51, 150000))), SendStatus::sent);  // 3 fragments

  Child pub(
      {peer(), "pub", "--url", url_for(port), "--channel", "LOOPED_DROP", "--raw", "--count", "5", "--size", "24"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(7, 5));
  const auto events = sink_.events(7);
  ASSERT_EQ(events.size(), 5u);
  for (std::size_t i = 0; i < events.size(); ++i) EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 24));
  EXPECT_EQ(adapter->statistics().received, 5u);
  EXPECT_EQ(adapter->statistics().overflow_drops, 0u);
  EXPECT_EQ(adapter->statistics().receive_errors, 0u);
  // The kernel did drop them: the receive socket's drop count (/proc/net/udp) is our 53 datagrams.
  EXPECT_EQ(udp_socket_drops(port), 53u);
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(53));
  adapter->stop();
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(53));

  // A new socket counts from 0 in the kernel and in the transmitter; the segment's figure goes on.
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);  // stop() forgot the channels
  for (std::uint32_t k = 52; k <= 53; ++k) ASSERT_EQ(adapter->send(outbound(7, own_pattern(k, 24))), SendStatus::sent);
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(55));
  Child more(
      {peer(), "pub", "--url", url_for(port), "--channel", "LOOPED_DROP", "--raw", "--count", "1", "--size", "24"});
  ASSERT_EQ(more.wait_exit(), std::optional<int>(0)) << more.stderr_text();
  ASSERT_TRUE(sink_.wait_events(7, 6));
  EXPECT_EQ(udp_socket_drops(port), 2u);
  EXPECT_EQ(adapter->statistics().overflow_drops, 0u);
  adapter->stop();
}

// A segment that receives no channel leaves the group: what it sends still reaches the group's
// other members but no longer loops back to its own receive socket (no drop of that socket,
// nothing in the host's InErrors, no own_datagrams_dropped). Binding a received channel joins it
// again before the channel is used; unbinding the last one leaves it again.
TEST_F(LcmAdapterTest, ASegmentThatOnlySendsLeavesTheGroupUntilAChannelIsReceived) {
  const int port = 7712;
  auto adapter = make(port);
  const ChannelBinding out = binding(8, "ONLY_OUT", HopRole::subscriber, LcmEncoding::raw, 13);
  const ChannelBinding in = binding(9, "NOW_IN", HopRole::publisher, LcmEncoding::raw, 14);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{out}).ok);

  Child sub(
      {peer(), "sub", "--url", url_for(port), "--channel", "ONLY_OUT", "--raw", "--count", "10", "--timeout", "10"});
  ASSERT_TRUE(sub.wait_stderr("READY")) << sub.stderr_text();
  for (std::uint32_t k = 1; k <= 10; ++k) ASSERT_EQ(adapter->send(outbound(8, own_pattern(k, 24))), SendStatus::sent);
  ASSERT_EQ(sub.wait_exit(), std::optional<int>(0)) << sub.stderr_text();
  EXPECT_EQ(sub.stdout_lines().size(), 10u);
  EXPECT_EQ(udp_socket_drops(port), 0u);
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(0));

  ASSERT_TRUE(adapter->configure(std::vector{out, in}).ok);
  for (std::uint32_t k = 11; k <= 15; ++k) ASSERT_EQ(adapter->send(outbound(8, own_pattern(k, 24))), SendStatus::sent);
  Child pub({peer(), "pub", "--url", url_for(port), "--channel", "NOW_IN", "--raw", "--count", "3", "--size", "24"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(9, 3));
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(sink_.events(9).at(i).payload, peer_pattern(i + 1, 24));
  EXPECT_EQ(udp_socket_drops(port), 5u);  // a member again: ours loop back and are dropped
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(5));

  ASSERT_TRUE(adapter->configure(std::vector{out}).ok);
  for (std::uint32_t k = 16; k <= 19; ++k) ASSERT_EQ(adapter->send(outbound(8, own_pattern(k, 24))), SendStatus::sent);
  EXPECT_EQ(adapter->statistics().sent, 19u);
  EXPECT_EQ(udp_socket_drops(port), 5u);
  EXPECT_EQ(adapter->statistics().transport_counter("own_datagrams_dropped"), std::optional<std::uint64_t>(5));
  EXPECT_EQ(adapter->statistics().overflow_drops, 0u);
  adapter->stop();
}

TEST_F(LcmAdapterTest, OwnRawMessagesAreNotReceivedBack) {
  const int port = 7706;
  segment_.lcm.own_datagrams = LcmOwnDatagrams::cut;
  auto adapter = make(port);
  const std::vector<ChannelBinding> bindings{binding(6, "LOOPED_RAW", HopRole::publisher, LcmEncoding::raw, 11),
                                             binding(6, "LOOPED_RAW", HopRole::subscriber, LcmEncoding::raw, 11)};
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(bindings).ok);

  // Raw messages carry no origin: only their source tells ours from a native program's.
  for (std::uint32_t k = 1; k <= 10; ++k) ASSERT_EQ(adapter->send(outbound(6, own_pattern(k, 24))), SendStatus::sent);

  Child pub(
      {peer(), "pub", "--url", url_for(port), "--channel", "LOOPED_RAW", "--raw", "--count", "5", "--size", "24"});
  ASSERT_EQ(pub.wait_exit(), std::optional<int>(0)) << pub.stderr_text();
  ASSERT_TRUE(sink_.wait_events(6, 5));

  const auto events = sink_.events(6);
  ASSERT_EQ(events.size(), 5u);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].payload, peer_pattern(i + 1, 24));
    EXPECT_EQ(events[i].header.subject, 11u);
  }
  EXPECT_EQ(sink_.problems(6, InboundProblem::own_echo), 0u);
  EXPECT_EQ(adapter->statistics().overflow_drops, 0u);
  EXPECT_EQ(adapter->statistics().receive_errors, 0u);
  adapter->stop();
}

}  // namespace
}  // namespace cosmic::lcm_test

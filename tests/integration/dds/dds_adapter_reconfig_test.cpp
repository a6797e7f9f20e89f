// The DDS segment adapter against real Fast DDS, continued (see dds_adapter_test.cpp): channel
// names as topic names and their collisions, native sequence numbers and arrival time, runtime
// reconfiguration (adding, removing and changing channels while events flow), discovery-server
// clients and configuration errors reported through Status. Native DDS programs
// (cosmic-dds-peer) run in separate processes, inside a fresh network namespace (ctest does,
// through scripts/netns-run); every test uses its own DDS domain id.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/utils/IPLocator.h>

#include "cosmic/dds_adapter.hpp"
#include "dds_adapter_fixture.hpp"
#include "test_support.hpp"

namespace cosmic::dds_test {
namespace {

// ---- topic names ------------------------------------------------------------------------------

TEST(DdsAdapter, ChannelNamesBecomeValidTopicNames) {
  EXPECT_EQ(dds_topic_name("robot.arm-left_2"), "cosmic/robot_arm_left_2");
  EXPECT_EQ(dds_topic_name("Imu0"), "cosmic/Imu0");
}

TEST(DdsAdapter, ChannelsMappingToOneTopicAreRefused) {
  Fixture f(dds_segment(63));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding running = binding(1, "keep", HopRole::subscriber);
  ASSERT_TRUE(f.adapter->configure(std::span(&running, 1)).ok);
  const ChannelBinding clash[] = {binding(1, "keep", HopRole::subscriber), binding(2, "arm-left", HopRole::subscriber),
                                  binding(3, "arm.left", HopRole::publisher)};
  const Status st = f.adapter->configure(clash);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.error.find("'arm-left'"), std::string::npos) << st.error;
  EXPECT_NE(st.error.find("'arm.left'"), std::string::npos) << st.error;
  EXPECT_NE(st.error.find("cosmic/arm_left"), std::string::npos) << st.error;
  // Issue 22, item 12 (SegmentAdapter::configure): the second channel on the topic is refused,
  // alone; the first one and the running channel are carried.
  ASSERT_EQ(st.refused.size(), 1u) << st.error;
  EXPECT_EQ(st.refused[0].channel, 3u);
  Child arm(peer({"sub", "--domain", "63", "--channel", "arm-left", "--count", "1", "--timeout", "30"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber)) << arm.describe();
  EXPECT_EQ(f.adapter->matched_endpoints(3, HopRole::publisher), 0u);
  // The running channel is untouched; one channel in both roles is no collision.
  Child sub(peer({"sub", "--domain", "63", "--channel", "keep", "--count", "1", "--timeout", "30"}));
  ASSERT_TRUE(f.matched(1, HopRole::subscriber)) << sub.describe();
  const ChannelBinding both[] = {binding(1, "keep", HopRole::subscriber), binding(1, "keep", HopRole::publisher)};
  EXPECT_TRUE(f.adapter->configure(both).ok);
}

// ---- native sequence numbers and arrival time ---------------------------------------------------

// A native publisher (origin 0) gets its writer's sample sequence number, whatever its envelope
// says; a gateway's envelope (origin != 0) keeps its own. received_at lies between the first
// write and the callback, on the steady clock.
TEST(DdsAdapter, NativePublisherSequenceIsItsSampleSequence) {
  Fixture f(dds_segment(64));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding bindings[] = {binding(3, "native", HopRole::publisher),
                                     binding(4, "relayed", HopRole::publisher)};
  ASSERT_TRUE(f.adapter->configure(bindings).ok);
  constexpr int kCount = 20;
  const auto steady = [] {
    return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch());
  };
  const Nanos before = steady();
  auto native = start_pub({"pub", "--domain", "64", "--channel", "native", "--count", std::to_string(kCount), "--size",
                           "8", "--origin", "0", "--first-sequence", "1000"},
                          f.reader_matched(3));
  auto relayed = start_pub({"pub", "--domain", "64", "--channel", "relayed", "--count", std::to_string(kCount),
                            "--size", "8", "--origin", "77", "--first-sequence", "1000"},
                           f.reader_matched(4));
  ASSERT_TRUE(f.sink.wait_count(3, kCount, kWait)) << native->describe();
  ASSERT_TRUE(f.sink.wait_count(4, kCount, kWait)) << relayed->describe();
  const Nanos after = steady();
  std::uint32_t native_q = 0;
  std::uint32_t relayed_q = 999;
  for (const auto& e : f.sink.events()) {
    EXPECT_GE(e.received_at, before);
    EXPECT_LE(e.received_at, after);
    if (e.channel == 3) {
      EXPECT_EQ(e.header.origin, 0u);
      EXPECT_EQ(e.header.sequence, ++native_q);
    } else {
      EXPECT_EQ(e.header.sequence, ++relayed_q);
    }
  }
  EXPECT_EQ(native_q, static_cast<std::uint32_t>(kCount));
}

// ---- runtime reconfiguration ------------------------------------------------------------------

TEST(DdsAdapter, AddingAChannelLosesNothingOnTheOthers) {
  Fixture f(dds_segment(46));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding flowing_in = binding(1, "in.flowing", HopRole::publisher);
  const ChannelBinding flowing_out = binding(2, "out.flowing", HopRole::subscriber);
  const ChannelBinding first[] = {flowing_in, flowing_out};
  ASSERT_TRUE(f.adapter->configure(first).ok);

  constexpr int kCount = 400;
  Child sub(peer({"sub", "--domain", "46", "--channel", "out.flowing", "--count", std::to_string(kCount), "--reliable",
                  "--quiet", "--timeout", "60"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();
  auto pub = start_pub({"pub", "--domain", "46", "--channel", "in.flowing", "--count", std::to_string(kCount), "--size",
                        "8", "--rate", "400"},
                       f.reader_matched(1));

  // The router thread keeps sending on the outgoing channel throughout.
  std::atomic<bool> sending_ok{true};
  std::thread router([&] {
    std::vector<std::uint8_t> storage;
    for (std::uint32_t q = 1; q <= kCount; ++q) {
      if (f.adapter->send(outbound(2, q, storage)) != SendStatus::sent) sending_ok = false;
      std::this_thread::sleep_for(2ms);  // pacing of the traffic, not a synchronisation
    }
  });

  ASSERT_TRUE(f.sink.wait_count(1, 50, kWait)) << pub->describe();
  const ChannelBinding added_in = binding(3, "in.added", HopRole::publisher);
  const ChannelBinding added_out = binding(4, "out.added", HopRole::subscriber);
  const ChannelBinding second[] = {flowing_in, flowing_out, added_in, added_out};
  ASSERT_TRUE(f.adapter->configure(second).ok);
  ASSERT_TRUE(f.adapter->configure(second).ok);  // idempotent
  EXPECT_LT(f.sink.count_on(1), static_cast<std::size_t>(kCount)) << "reconfigured too late";

  router.join();
  EXPECT_TRUE(sending_ok);
  ASSERT_EQ(pub->wait_exit(60s), 0) << pub->describe();
  ASSERT_TRUE(f.sink.wait_count(1, kCount, kWait)) << [&] {
    std::set<std::uint32_t> got;
    for (const auto& e : f.sink.events_on(1)) got.insert(e.header.sequence);
    std::string text = "received " + std::to_string(got.size()) + ", missing:";
    for (std::uint32_t q = 1; q <= kCount; ++q) {
      if (got.count(q) == 0) text += " " + std::to_string(q);
    }
    return text + "\n" + pub->describe();
  }();
  ASSERT_EQ(sub.wait_exit(60s), 0) << sub.describe();

  // Every event of the flowing channel exactly once, in order.
  const auto events = f.sink.events_on(1);
  ASSERT_EQ(events.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t q = 1; q <= kCount; ++q) EXPECT_EQ(events[q - 1].header.sequence, q);

  // The added channels work in both directions.
  auto pub_added =
      start_pub({"pub", "--domain", "46", "--channel", "in.added", "--count", "5", "--size", "8"}, f.reader_matched(3));
  ASSERT_TRUE(f.sink.wait_count(3, 5, kWait)) << pub_added->describe();
  Child sub_added(peer({"sub", "--domain", "46", "--channel", "out.added", "--count", "3", "--reliable"}));
  ASSERT_TRUE(f.matched(4, HopRole::subscriber)) << sub_added.describe();
  ASSERT_TRUE(sub_added.wait_err(matched_at_least(1), kWait)) << sub_added.describe();
  std::vector<std::uint8_t> storage;
  for (std::uint32_t q = 1; q <= 3; ++q) {
    ASSERT_EQ(f.adapter->send(outbound(4, q, storage)), SendStatus::sent);
  }
  EXPECT_EQ(sub_added.wait_exit(kWait), 0) << sub_added.describe();
}

TEST(DdsAdapter, RemovingAChannelStopsItsDelivery) {
  Fixture f(dds_segment(47));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding kept = binding(1, "kept", HopRole::publisher);
  const ChannelBinding removed_in = binding(2, "removed.in", HopRole::publisher);
  const ChannelBinding removed_out = binding(3, "removed.out", HopRole::subscriber);
  const ChannelBinding all[] = {kept, removed_in, removed_out};
  ASSERT_TRUE(f.adapter->configure(all).ok);

  {
    auto pub = start_pub({"pub", "--domain", "47", "--channel", "removed.in", "--count", "5", "--size", "4"},
                         f.reader_matched(2));
    ASSERT_TRUE(f.sink.wait_count(2, 5, kWait)) << pub->describe();
    ASSERT_EQ(pub->wait_exit(kWait), 0);
  }

  ASSERT_TRUE(f.adapter->configure(std::span(&kept, 1)).ok);
  EXPECT_EQ(f.adapter->matched_endpoints(2, HopRole::publisher), 0u);
  std::vector<std::uint8_t> storage;
  EXPECT_EQ(f.adapter->send(outbound(3, 1, storage)), SendStatus::failed);

  // On the DDS side nobody reads the removed channel any more...
  Child orphan(peer(
      {"pub", "--domain", "47", "--channel", "removed.in", "--count", "5", "--size", "4", "--match-timeout", "3"}));
  // ...while the kept channel still flows.
  auto pub =
      start_pub({"pub", "--domain", "47", "--channel", "kept", "--count", "20", "--size", "4"}, f.reader_matched(1));
  ASSERT_TRUE(f.sink.wait_count(1, 20, kWait)) << pub->describe();
  EXPECT_EQ(orphan.wait_exit(kWait), 2) << orphan.describe();  // no subscriber matched
  EXPECT_EQ(f.sink.count_on(2), 5u);
}

TEST(DdsAdapter, ChangedChannelQosReplacesTheEndpoint) {
  Fixture f(dds_segment(52));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  ChannelBinding b = binding(4, "odometry", HopRole::subscriber);
  b.spec.temp_validity = Nanos(20'000'000);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
  Child sub(peer({"sub", "--domain", "52", "--channel", "odometry", "--count", "1", "--reliable", "--timeout", "30"}));
  auto announced_lifespan = [&](std::int64_t ns) {
    return [ns](const std::string& line) {
      const json j = parse(line);
      return diag_event("publication")(line) && j["lifespan_ns"] == ns;
    };
  };
  ASSERT_TRUE(sub.wait_err(announced_lifespan(20'000'000), kWait)) << sub.describe();
  b.spec.temp_validity = Nanos(40'000'000);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
  ASSERT_TRUE(sub.wait_err(announced_lifespan(40'000'000), kWait)) << sub.describe();
  // The new writer carries the channel. The reader saw the old writer match, the new one match
  // and the old one leave (in some order): three changes, ending with exactly one writer.
  ASSERT_TRUE(f.matched(4, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(test::eventually(
      [&] {
        std::vector<int> counts;
        for (const auto& line : sub.err_lines()) {
          if (diag_event("matched")(line)) counts.push_back(parse(line)["count"].get<int>());
        }
        return counts.size() >= 3 && counts.back() == 1;
      },
      kWait))
      << sub.describe();
  std::vector<std::uint8_t> storage;
  ASSERT_EQ(f.adapter->send(outbound(4, 1, storage)), SendStatus::sent);
  EXPECT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
}

TEST(DdsAdapter, DiscoveryServerClients) {
  namespace fdds = eprosima::fastdds::dds;
  namespace rtps = eprosima::fastrtps::rtps;
  constexpr std::uint32_t kDomain = 53;
  // A discovery server (id 0) on 127.0.0.1:11811, in this process.
  fdds::DomainParticipantQos server_qos = fdds::PARTICIPANT_QOS_DEFAULT;
  server_qos.wire_protocol().builtin.discovery_config.discoveryProtocol = rtps::DiscoveryProtocol_t::SERVER;
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(0, server_qos.wire_protocol().prefix);
  rtps::Locator_t locator;
  rtps::IPLocator::setIPv4(locator, "127.0.0.1");
  locator.port = 11811;
  server_qos.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(locator);
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  fdds::DomainParticipant* server = factory->create_participant(kDomain, server_qos);
  ASSERT_NE(server, nullptr);

  SegmentSpec spec = dds_segment(kDomain);
  spec.dds.discovery_server = "127.0.0.1:11811";
  {
    Fixture sender(spec, 1001);
    Fixture receiver(spec, 1002);
    ASSERT_TRUE(sender.adapter->start(sender.sink).ok);
    ASSERT_TRUE(receiver.adapter->start(receiver.sink).ok);
    const ChannelBinding out = binding(6, "via.server", HopRole::subscriber);
    const ChannelBinding in = binding(6, "via.server", HopRole::publisher);
    ASSERT_TRUE(sender.adapter->configure(std::span(&out, 1)).ok);
    ASSERT_TRUE(receiver.adapter->configure(std::span(&in, 1)).ok);
    ASSERT_TRUE(sender.matched(6, HopRole::subscriber));
    ASSERT_TRUE(receiver.matched(6, HopRole::publisher));
    std::vector<std::uint8_t> storage;
    for (std::uint32_t q = 1; q <= 5; ++q) {
      ASSERT_EQ(sender.adapter->send(outbound(6, q, storage, 1001)), SendStatus::sent);
    }
    ASSERT_TRUE(receiver.sink.wait_count(6, 5, kWait));
  }
  factory->delete_participant(server);
}

// ---- configuration errors ---------------------------------------------------------------------

TEST(DdsAdapter, ReportsBadConfigurationThroughStatus) {
  test::StderrLogger log;
  RecordingSink sink;
  {
    auto adapter = make_dds_segment_adapter(dds_segment(49), self_identity(), log);
    const ChannelBinding b = binding(1, "x", HopRole::publisher);
    EXPECT_FALSE(adapter->configure(std::span(&b, 1)).ok);  // not started
    EXPECT_EQ(adapter->health().state, SegmentHealth::down);
    std::vector<std::uint8_t> storage;
    EXPECT_EQ(adapter->send(outbound(1, 1, storage)), SendStatus::failed);
    adapter->stop();  // idempotent, also when never started
  }
  {
    SegmentSpec spec = dds_segment(49);
    spec.dds.interfaces = {"10.254.254.254"};
    auto adapter = make_dds_adapter(spec, self_identity(), log);
    const Status st = adapter->start(sink);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.error.find("10.254.254.254"), std::string::npos) << st.error;
    EXPECT_EQ(adapter->health().state, SegmentHealth::down);
    EXPECT_FALSE(adapter->health().detail.empty());
  }
  {
    SegmentSpec spec = dds_segment(49);
    spec.dds.interfaces = {"no-such-if0"};
    EXPECT_FALSE(make_dds_adapter(spec, self_identity(), log)->start(sink).ok);
  }
  for (const char* server : {"127.0.0.1", "localhost:11811", "127.0.0.1:99999"}) {
    SegmentSpec spec = dds_segment(49);
    spec.dds.discovery_server = server;
    EXPECT_FALSE(make_dds_adapter(spec, self_identity(), log)->start(sink).ok) << server;
  }
  {
    SegmentSpec spec = dds_segment(250);
    auto adapter = make_dds_adapter(spec, self_identity(), log);
    EXPECT_FALSE(adapter->start(sink).ok);
    EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  }
  {
    auto adapter = make_dds_segment_adapter(dds_segment(49), self_identity(), log);
    ASSERT_TRUE(adapter->start(sink).ok);
    EXPECT_FALSE(adapter->start(sink).ok);  // twice
    const ChannelBinding dup[] = {binding(1, "x", HopRole::publisher), binding(1, "x", HopRole::publisher)};
    const Status twice = adapter->configure(dup);
    EXPECT_FALSE(twice.ok);
    ASSERT_EQ(twice.refused.size(), 1u) << twice.error;
    EXPECT_EQ(twice.refused[0].channel, 1u);
    ChannelBinding nameless = binding(2, "", HopRole::subscriber);
    const Status no_name = adapter->configure(std::span(&nameless, 1));
    EXPECT_FALSE(no_name.ok);
    ASSERT_EQ(no_name.refused.size(), 1u) << no_name.error;
    EXPECT_EQ(no_name.refused[0].channel, 2u);
    std::vector<std::uint8_t> storage;
    EXPECT_EQ(adapter->send(outbound(42, 1, storage)), SendStatus::failed);  // unknown channel
    EXPECT_EQ(adapter->statistics().send_errors, 1u);
    adapter->stop();
    adapter->stop();
    EXPECT_EQ(adapter->health().state, SegmentHealth::down);
  }
}

TEST(DdsAdapter, InterfaceAllowListByAddressAndName) {
  for (const char* allowed : {"127.0.0.1", "lo"}) {
    SCOPED_TRACE(allowed);
    const std::uint32_t domain = allowed[0] == '1' ? 50 : 51;
    SegmentSpec spec = dds_segment(domain);
    spec.dds.interfaces = {allowed};
    Fixture f(spec);
    ASSERT_TRUE(f.adapter->start(f.sink).ok);
    const ChannelBinding b = binding(1, "allowed", HopRole::publisher);
    ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
    auto pub =
        start_pub({"pub", "--domain", std::to_string(domain), "--channel", "allowed", "--count", "5", "--size", "4"},
                  f.reader_matched(1));
    ASSERT_TRUE(f.sink.wait_count(1, 5, kWait)) << pub->describe();
    EXPECT_EQ(pub->wait_exit(kWait), 0) << pub->describe();
  }
}

}  // namespace
}  // namespace cosmic::dds_test

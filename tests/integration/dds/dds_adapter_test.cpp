// The DDS segment adapter against real Fast DDS: the adapter runs in this process, native DDS
// programs (cosmic-dds-peer) in separate processes. Run inside a fresh network namespace
// (ctest does, through scripts/netns-run); every test uses its own DDS domain id.
// This file: the thread policy of Fast DDS's threads and the participant per class, envelopes
// to and from native peers, own publications and the QoS on the wire. Topic names, native
// sequence numbers, runtime reconfiguration, discovery servers and configuration errors are in
// dds_adapter_reconfig_test.cpp; the shared helpers in dds_adapter_fixture.hpp.
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <chrono>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/dds_adapter.hpp"
#include "dds_adapter_fixture.hpp"
#include "test_support.hpp"

namespace cosmic::dds_test {
namespace {

// ---- thread policy ----------------------------------------------------------------------------

// How many of this process's threads are named `name`; each must be pinned to CPU 0 alone and
// run at `nice` (a failed expectation names the thread).
std::size_t threads_running_on_cpu0_at_nice(const std::string& name, int nice) {
  std::size_t found = 0;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string comm;
    std::getline(std::ifstream(task.path() / "comm"), comm);
    if (comm != name) continue;
    const pid_t tid = static_cast<pid_t>(std::stol(task.path().filename().string()));
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    EXPECT_EQ(sched_getaffinity(tid, sizeof cpus, &cpus), 0) << "thread " << tid;
    EXPECT_EQ(CPU_COUNT(&cpus), 1) << "thread " << tid;
    EXPECT_TRUE(CPU_ISSET(0, &cpus)) << "thread " << tid;
    errno = 0;
    EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(tid)), nice) << "thread " << tid;
    ++found;
  }
  return found;
}

// Fast DDS's threads of a segment run as gateway.realtime's receive policy says: they inherit it
// from the thread the adapter creates the participant on (nice and affinity here, which need no
// privilege; SCHED_FIFO is inherited the same way).
TEST(DdsAdapter, FastDdsThreadsInheritTheReceivePolicy) {
  Fixture f(dds_segment(65));
  errno = 0;
  const int own_nice = getpriority(PRIO_PROCESS, 0);
  f.sink.set_receive_thread_policy(ThreadPolicy{"rx", 0, 7, {0}});
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const std::string name = "rx:" + f.spec.name;
  EXPECT_GE(threads_running_on_cpu0_at_nice(name, 7), 2u)
      << "Fast DDS's receive and event threads should carry the name " << name;
  // The test's own thread is untouched.
  errno = 0;
  EXPECT_EQ(getpriority(PRIO_PROCESS, 0), own_nice);
}

// Each class of channel has a participant of its own, so an NRT write never holds the send lock,
// shared-memory segment or threads an HRT write needs; its Fast DDS threads run as that class's
// lane does (here: nice and affinity, which need no privilege; SCHED_FIFO is inherited the same
// way). A channel moved to another class moves to that class's participant.
TEST(DdsAdapter, EachClassHasAParticipantOfItsOwn) {
  Fixture f(dds_segment(66));
  f.sink.set_class_thread_policy(ChannelClass::hrt, ThreadPolicy{"ignored", 0, 6, {0}});
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  ChannelBinding hrt = binding(1, "ctl.hrt", HopRole::subscriber);
  hrt.spec.cls = ChannelClass::hrt;
  ChannelBinding nrt = binding(2, "log.nrt", HopRole::subscriber);
  nrt.spec.cls = ChannelClass::nrt;
  ChannelBinding srt = binding(3, "cam.srt", HopRole::subscriber);
  srt.spec.cls = ChannelClass::srt;
  const ChannelBinding all[] = {hrt, nrt, srt};
  ASSERT_TRUE(f.adapter->configure(all).ok);

  // The participant each writer lives in, as a native subscriber discovers it.
  auto writer_participant = [&](const std::string& topic) {
    Child sub(peer({"sub", "--domain", "66", "--topic", topic, "--count", "1", "--reliable", "--timeout", "30"}));
    std::string participant;
    EXPECT_TRUE(sub.wait_err(
        [&](const std::string& line) {
          const json j = parse(line);
          if (!j.is_object() || j.value("event", "") != "publication") return false;
          participant = j.value("participant", "");
          return true;
        },
        kWait))
        << sub.describe();
    return participant;
  };
  const std::string hrt_home = writer_participant("cosmic/ctl_hrt");
  const std::string nrt_home = writer_participant("cosmic/log_nrt");
  const std::string srt_home = writer_participant("cosmic/cam_srt");
  ASSERT_FALSE(hrt_home.empty());
  ASSERT_FALSE(nrt_home.empty());
  ASSERT_FALSE(srt_home.empty());
  EXPECT_NE(hrt_home, nrt_home);
  EXPECT_NE(hrt_home, srt_home);
  EXPECT_NE(srt_home, nrt_home);

  // The HRT participant's Fast DDS threads run as the HRT lane does.
  const std::string name = "rx-hrt:" + f.spec.name;
  EXPECT_GE(threads_running_on_cpu0_at_nice(name, 6), 2u)
      << "the HRT participant's threads should carry the name " << name;

  // Events still flow on every class; the NRT channel moved to HRT lands in the HRT participant.
  nrt.spec.cls = ChannelClass::hrt;
  const ChannelBinding moved[] = {hrt, nrt, srt};
  ASSERT_TRUE(f.adapter->configure(moved).ok);
  EXPECT_EQ(writer_participant("cosmic/log_nrt"), hrt_home);
  Child sub(
      peer({"sub", "--domain", "66", "--topic", "cosmic/log_nrt", "--count", "3", "--reliable", "--timeout", "30"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();
  std::vector<std::uint8_t> storage;
  for (std::uint32_t q = 1; q <= 3; ++q) {
    ASSERT_EQ(f.adapter->send(outbound(2, q, storage)), SendStatus::sent);
  }
  ASSERT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
  EXPECT_EQ(sub.out_lines().size(), 3u);
}

// The HRT participant speaks UDP alone by default, to peers on this host too: under an NRT flood
// Fast DDS's shared-memory path held HRT samples back for up to 10 ms and let them go in a bunch
// (scripts/bench, HRT under flood), UDP did not. The other classes keep shared memory, and
// `shared_memory` gives it back to HRT. What a native subscriber discovers is what it would use.
TEST(DdsAdapter, HrtParticipantSpeaksUdpAloneUnlessSharedMemoryIsAsked) {
  for (const bool hrt_shared : {false, true}) {
    SCOPED_TRACE(hrt_shared ? "shared_memory: [hrt, srt, nrt]" : "default");
    const std::uint32_t domain = hrt_shared ? 68 : 67;
    SegmentSpec spec = dds_segment(domain);
    if (hrt_shared) spec.dds.shared_memory = {true, true, true};
    Fixture f(spec);
    ASSERT_TRUE(f.adapter->start(f.sink).ok);
    ChannelBinding hrt = binding(1, "ctl.hrt", HopRole::subscriber);
    hrt.spec.cls = ChannelClass::hrt;
    ChannelBinding nrt = binding(2, "log.nrt", HopRole::subscriber);
    const ChannelBinding all[] = {hrt, nrt};
    ASSERT_TRUE(f.adapter->configure(all).ok);
    auto transports_of = [&](const std::string& topic) {
      Child sub(peer({"sub", "--domain", std::to_string(domain), "--topic", topic, "--count", "1", "--timeout", "30"}));
      json kinds;
      EXPECT_TRUE(sub.wait_err(
          [&](const std::string& line) {
            const json j = parse(line);
            if (!j.is_object() || j.value("event", "") != "publication") return false;
            kinds = j.value("transports", json::array());
            return true;
          },
          kWait))
          << sub.describe();
      return kinds;
    };
    const json hrt_kinds = transports_of("cosmic/ctl_hrt");
    const json nrt_kinds = transports_of("cosmic/log_nrt");
    auto has = [](const json& kinds, const char* kind) {
      return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
    };
    EXPECT_TRUE(has(hrt_kinds, "udpv4")) << hrt_kinds.dump();
    EXPECT_EQ(has(hrt_kinds, "shm"), hrt_shared) << hrt_kinds.dump();
    EXPECT_TRUE(has(nrt_kinds, "shm")) << nrt_kinds.dump();
  }
}

// ---- adapter -> native subscriber -------------------------------------------------------------

TEST(DdsAdapter, SendsEnvelopesToNativeSubscriber) {
  Fixture f(dds_segment(41));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  EXPECT_EQ(f.adapter->health().state, SegmentHealth::up);
  const ChannelBinding b = binding(7, "robot.pose", HopRole::subscriber);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);

  constexpr int kCount = 50;
  Child sub(peer({"sub", "--domain", "41", "--topic", "cosmic/robot_pose", "--count", std::to_string(kCount),
                  "--reliable", "--timeout", "30"}));
  // Discovery done in both directions: our writer sees the reader, the reader sees our writer.
  ASSERT_TRUE(f.matched(7, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();

  std::vector<std::uint8_t> storage;
  for (std::uint32_t q = 1; q <= kCount; ++q) {
    ASSERT_EQ(f.adapter->send(outbound(7, q, storage)), SendStatus::sent);
  }
  ASSERT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
  const auto lines = sub.out_lines();
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t q = 1; q <= kCount; ++q) {
    const json j = parse(lines[q - 1]);
    ASSERT_TRUE(j.is_object()) << lines[q - 1];
    EXPECT_EQ(j["subject"], 0xABCDEF);
    EXPECT_EQ(j["origin"], kSelfId);
    EXPECT_EQ(j["sequence"], q);
    EXPECT_EQ(j["hop_count"], 1);
    EXPECT_EQ(j["created_ns"], 1'000'000 + q);
    EXPECT_EQ(j["age_ns"], 1000 * q);
    std::vector<std::uint8_t> expected(16);
    for (std::size_t i = 0; i < 16; ++i) expected[i] = pattern(q, i);
    EXPECT_EQ(j["payload"], hex(expected));
  }
  const AdapterStatistics stats = f.adapter->statistics();
  EXPECT_EQ(stats.sent, static_cast<std::uint64_t>(kCount));
  EXPECT_EQ(stats.send_errors, 0u);
}

// ---- native publisher -> adapter --------------------------------------------------------------

TEST(DdsAdapter, DeliversEnvelopesFromNativePublisher) {
  Fixture f(dds_segment(42));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding b = binding(3, "lidar.scan", HopRole::publisher);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);

  constexpr int kCount = 100;
  auto pub = start_pub({"pub", "--domain", "42", "--channel", "lidar.scan", "--count", std::to_string(kCount), "--size",
                        "24", "--subject", "99", "--origin", "4242", "--hop-count", "2", "--age-ns", "777"},
                       f.reader_matched(3));
  ASSERT_TRUE(f.sink.wait_count(3, kCount, kWait)) << pub->describe();
  ASSERT_EQ(pub->wait_exit(kWait), 0) << pub->describe();

  const auto events = f.sink.events();
  ASSERT_EQ(events.size(), static_cast<std::size_t>(kCount));
  for (std::uint32_t q = 1; q <= kCount; ++q) {
    const auto& e = events[q - 1];
    EXPECT_EQ(e.channel, 3u);
    EXPECT_EQ(e.header.subject, 99u);
    EXPECT_EQ(e.header.origin, 4242u);
    EXPECT_EQ(e.header.sequence, q);
    EXPECT_EQ(e.header.hop_count, 2);
    EXPECT_EQ(e.header.age_ns, 777);
    ASSERT_EQ(e.payload.size(), 24u);
    for (std::size_t i = 0; i < 24; ++i) {
      ASSERT_EQ(e.payload[i], static_cast<std::uint8_t>((q + i) & 0xff));
    }
    EXPECT_GT(e.received_at.count(), 0);
  }
  EXPECT_EQ(f.adapter->statistics().received, static_cast<std::uint64_t>(kCount));
}

TEST(DdsAdapter, OversizedPayloadIsADecodeError) {
  SegmentSpec spec = dds_segment(48);
  spec.max_message_size = 32;
  Fixture f(spec);
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding b = binding(1, "big", HopRole::publisher);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
  auto big =
      start_pub({"pub", "--domain", "48", "--channel", "big", "--count", "3", "--size", "33"}, f.reader_matched(1));
  ASSERT_TRUE(f.sink.wait_problems(InboundProblem::decode_error, 3, kWait)) << big->describe();
  ASSERT_EQ(big->wait_exit(kWait), 0) << big->describe();
  ASSERT_TRUE(test::eventually([&] { return !f.reader_matched(1)(); }, kWait));
  auto small =
      start_pub({"pub", "--domain", "48", "--channel", "big", "--count", "2", "--size", "32"}, f.reader_matched(1));
  ASSERT_TRUE(f.sink.wait_count(1, 2, kWait)) << small->describe();
  EXPECT_EQ(f.adapter->statistics().receive_errors, 3u);

  // The send side refuses what the segment cannot carry.
  const ChannelBinding w = binding(2, "big.out", HopRole::subscriber);
  const ChannelBinding both[] = {b, w};
  ASSERT_TRUE(f.adapter->configure(both).ok);
  std::vector<std::uint8_t> storage;
  EXPECT_EQ(f.adapter->send(outbound(2, 1, storage, kSelfId, 33)), SendStatus::failed);
  EXPECT_EQ(f.adapter->send(outbound(2, 1, storage, kSelfId, 32)), SendStatus::sent);
}

// ---- own publications -------------------------------------------------------------------------

TEST(DdsAdapter, NeverReceivesItsOwnPublications) {
  // A: the channel bound in both roles (its reader and writer share one participant).
  // B: another participant of the same gateway identity, receiving the channel.
  Fixture a(dds_segment(43));
  Fixture b(dds_segment(43));
  ASSERT_TRUE(a.adapter->start(a.sink).ok);
  ASSERT_TRUE(b.adapter->start(b.sink).ok);
  const ChannelBinding both[] = {binding(5, "echo", HopRole::subscriber), binding(5, "echo", HopRole::publisher)};
  ASSERT_TRUE(a.adapter->configure(both).ok);
  const ChannelBinding recv = binding(5, "echo", HopRole::publisher);
  ASSERT_TRUE(b.adapter->configure(std::span(&recv, 1)).ok);

  Child sub(peer({"sub", "--domain", "43", "--channel", "echo", "--count", "10", "--reliable"}));
  // A's writer: A's own reader, B's reader and the peer's reader.
  ASSERT_TRUE(a.matched(5, HopRole::subscriber, 3)) << sub.describe();
  ASSERT_TRUE(a.matched(5, HopRole::publisher, 1));
  ASSERT_TRUE(b.matched(5, HopRole::publisher, 1));
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();

  std::vector<std::uint8_t> storage;
  for (std::uint32_t q = 1; q <= 5; ++q) {  // originated by this gateway
    ASSERT_EQ(a.adapter->send(outbound(5, q, storage, kSelfId)), SendStatus::sent);
  }
  for (std::uint32_t q = 6; q <= 10; ++q) {  // forwarded on behalf of another gateway
    ASSERT_EQ(a.adapter->send(outbound(5, q, storage, 777)), SendStatus::sent);
  }
  // The events did go out...
  ASSERT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
  // ...A dropped all ten as its own echoes (same participant). B, another participant of the same
  // gateway identity, delivers all ten: the five carrying its own origin are a loop copy or a
  // spoof, which the router's ingress check drops and counts (never silently).
  ASSERT_TRUE(a.sink.wait_problems(InboundProblem::own_echo, 10, kWait));
  ASSERT_TRUE(b.sink.wait_count(5, 10, kWait));
  EXPECT_TRUE(a.sink.events().empty());
  EXPECT_EQ(b.sink.problems(InboundProblem::own_echo), 0u);
  std::size_t own_origin = 0;
  for (const auto& e : b.sink.events()) own_origin += e.header.origin == kSelfId ? 1 : 0;
  EXPECT_EQ(own_origin, 5u);

  // A native publisher claiming this gateway's origin is delivered to both, for the router to count.
  auto forged = start_pub({"pub", "--domain", "43", "--channel", "echo", "--count", "3", "--size", "4", "--origin",
                           std::to_string(kSelfId), "--wait-subscribers", "2"},
                          [&] { return a.reader_matched(5, 2)() && b.reader_matched(5, 2)(); });
  ASSERT_TRUE(a.sink.wait_count(5, 3, kWait)) << forged->describe();
  ASSERT_TRUE(b.sink.wait_count(5, 13, kWait)) << forged->describe();
  ASSERT_EQ(forged->wait_exit(kWait), 0) << forged->describe();
  EXPECT_EQ(a.sink.problems(InboundProblem::own_echo), 10u);
  for (const auto& e : a.sink.events()) EXPECT_EQ(e.header.origin, kSelfId);
}

// Each participant's receive threads carry one class, so the adapter tells the router which
// (InboundEvent::receiver_class) and the router may send the event on from that thread. Not for
// NRT while those threads run SCHED_FIFO (gateway.realtime.priorities.receive) and the NRT lanes
// are time-shared: the receive thread would write NRT events above the SRT lanes.
TEST(DdsAdapter, EventsCarryTheClassTheirReceiveThreadMaySendOn) {
  Fixture writer(dds_segment(59));
  Fixture reader(dds_segment(59));
  reader.sink.set_receive_thread_policy(ThreadPolicy{"ignored", 2, 0, {}});
  ASSERT_TRUE(writer.adapter->start(writer.sink).ok);
  ASSERT_TRUE(reader.adapter->start(reader.sink).ok);
  ChannelBinding srt_out = binding(3, "cam.srt", HopRole::subscriber);
  ChannelBinding srt_in = binding(3, "cam.srt", HopRole::publisher);
  srt_out.spec.cls = srt_in.spec.cls = ChannelClass::srt;
  ChannelBinding nrt_out = binding(4, "log.nrt", HopRole::subscriber);
  ChannelBinding nrt_in = binding(4, "log.nrt", HopRole::publisher);
  nrt_out.spec.cls = nrt_in.spec.cls = ChannelClass::nrt;
  const ChannelBinding outs[] = {srt_out, nrt_out};
  const ChannelBinding ins[] = {srt_in, nrt_in};
  ASSERT_TRUE(writer.adapter->configure(outs).ok);
  ASSERT_TRUE(reader.adapter->configure(ins).ok);
  for (const ChannelId id : {ChannelId{3}, ChannelId{4}}) {
    ASSERT_TRUE(writer.matched(id, HopRole::subscriber));
    ASSERT_TRUE(reader.matched(id, HopRole::publisher));
  }

  std::vector<std::uint8_t> storage;
  ASSERT_EQ(writer.adapter->send(outbound(3, 1, storage)), SendStatus::sent);
  ASSERT_EQ(writer.adapter->send(outbound(4, 1, storage)), SendStatus::sent);
  ASSERT_TRUE(reader.sink.wait_count(3, 1, kWait));
  ASSERT_TRUE(reader.sink.wait_count(4, 1, kWait));
  EXPECT_EQ(reader.sink.events_on(3)[0].receiver_class, ChannelClass::srt);
  EXPECT_FALSE(reader.sink.events_on(4)[0].receiver_class.has_value())
      << "a SCHED_FIFO receive thread must not write time-shared NRT events";
}

// ---- QoS on the wire --------------------------------------------------------------------------

// What a channel's writer offers is what a default reader of any vendor accepts: reliable,
// non-volatile, no deadline (not even from `period`), latency budget 0; lifespan = validity.
TEST(DdsAdapter, WritersOfferWhatDefaultReadersAccept) {
  Fixture f(dds_segment(44));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  ChannelBinding b = binding(9, "imu", HopRole::subscriber, 3);
  b.spec.period = Nanos(10'000'000);
  b.spec.temp_validity = Nanos(50'000'000);
  b.spec.reaction_time = Nanos(5'000'000);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);

  Child sub(peer({"sub", "--domain", "44", "--channel", "imu", "--count", "0", "--timeout", "30"}));
  ASSERT_TRUE(sub.wait_err(diag_event("publication"), kWait)) << sub.describe();
  json announced;
  for (const auto& line : sub.err_lines()) {
    if (diag_event("publication")(line)) announced = parse(line);
  }
  EXPECT_EQ(announced["topic"], "cosmic/imu");
  EXPECT_EQ(announced["reliability"], "reliable");
  EXPECT_EQ(announced["durability"], "non_volatile");
  EXPECT_TRUE(announced["deadline_ns"].is_null()) << announced;
  EXPECT_EQ(announced["lifespan_ns"], 50'000'000);
  EXPECT_EQ(announced["latency_budget_ns"], 0);
  ASSERT_TRUE(f.matched(9, HopRole::subscriber)) << sub.describe();
  EXPECT_EQ(f.adapter->incompatible_peers(9), 0u);
}

// Even on a best-effort segment the writer is reliable, so both kinds of reader match.
TEST(DdsAdapter, WritersServeReliableAndBestEffortReaders) {
  Fixture f(dds_segment(45, Reliability::best_effort));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding b = binding(2, "status", HopRole::subscriber);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);

  Child reliable(
      peer({"sub", "--domain", "45", "--channel", "status", "--count", "1", "--reliable", "--timeout", "30"}));
  Child best(peer({"sub", "--domain", "45", "--channel", "status", "--count", "1", "--timeout", "30"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber, 2)) << reliable.describe() << best.describe();
  ASSERT_TRUE(reliable.wait_err(matched_at_least(1), kWait)) << reliable.describe();
  ASSERT_TRUE(best.wait_err(matched_at_least(1), kWait)) << best.describe();
  std::vector<std::uint8_t> storage;
  ASSERT_EQ(f.adapter->send(outbound(2, 1, storage)), SendStatus::sent);
  EXPECT_EQ(reliable.wait_exit(kWait), 0) << reliable.describe();
  EXPECT_EQ(best.wait_exit(kWait), 0) << best.describe();
  EXPECT_EQ(f.adapter->incompatible_peers(2), 0u);
}

// A transient-local reader (e.g. a late-joining ROS 2 tool) is served by our writer.
TEST(DdsAdapter, TransientLocalReadersMatch) {
  Fixture f(dds_segment(60));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding b = binding(5, "map", HopRole::subscriber);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
  Child sub(peer({"sub", "--domain", "60", "--channel", "map", "--count", "1", "--reliable", "--transient-local",
                  "--timeout", "30"}));
  ASSERT_TRUE(f.matched(5, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();
  std::vector<std::uint8_t> storage;
  ASSERT_EQ(f.adapter->send(outbound(5, 1, storage)), SendStatus::sent);
  EXPECT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
  EXPECT_EQ(f.adapter->incompatible_peers(5), 0u);
}

// On a reliable segment a best-effort writer cannot match our reliable reader (DDS rule): the
// refusal is a per-channel count, not only a log line.
TEST(DdsAdapter, IncompatibleRemoteWriterIsCountedPerChannel) {
  Fixture f(dds_segment(61));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding bindings[] = {binding(6, "wheel", HopRole::publisher), binding(8, "other", HopRole::publisher)};
  ASSERT_TRUE(f.adapter->configure(bindings).ok);
  EXPECT_EQ(f.adapter->incompatible_peers(6), 0u);
  Child pub(peer({"pub", "--domain", "61", "--channel", "wheel", "--count", "1", "--size", "8", "--best-effort",
                  "--match-timeout", "30"}));
  ASSERT_TRUE(test::eventually([&] { return f.adapter->incompatible_peers(6) >= 1u; }, kWait)) << pub.describe();
  EXPECT_EQ(f.adapter->matched_endpoints(6, HopRole::publisher), 0u);
  EXPECT_EQ(f.adapter->incompatible_peers(8), 0u);
  EXPECT_EQ(f.adapter->incompatible_peers(99), 0u);  // not bound: nothing refused
}

// A best-effort segment's reader accepts a best-effort writer.
TEST(DdsAdapter, BestEffortSegmentAcceptsBestEffortWriters) {
  Fixture f(dds_segment(62, Reliability::best_effort));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  const ChannelBinding b = binding(6, "wheel", HopRole::publisher);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);
  // Best effort may lose samples (a loaded host, a shared-memory segment being recycled), so a
  // steady stream is offered and one delivered sample proves the match.
  auto pub = start_pub({"pub", "--domain", "62", "--channel", "wheel", "--count", "200", "--rate", "100", "--size", "8",
                        "--best-effort"},
                       f.reader_matched(6));
  ASSERT_TRUE(f.sink.wait_count(6, 1, kWait)) << pub->describe();
  EXPECT_EQ(f.adapter->incompatible_peers(6), 0u);
}

}  // namespace
}  // namespace cosmic::dds_test

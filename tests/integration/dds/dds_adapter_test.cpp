// The DDS segment adapter against real Fast DDS: the adapter runs in this process, native DDS
// programs (cosmic-dds-peer) in separate processes. Run inside a fresh network namespace
// (ctest does, through scripts/netns-run); every test uses its own DDS domain id.
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/resource.h>

#include <atomic>
#include <filesystem>
#include <fstream>
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
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using json = nlohmann::json;
using test::Child;
using test::RecordingSink;

constexpr std::uint64_t kSelfId = 0xC05A1C0001ULL;
constexpr auto kWait = 20s;

GatewayIdentity self_identity() { return GatewayIdentity{kSelfId, "gw-test"}; }

SegmentSpec dds_segment(std::uint32_t domain, Reliability reliability = Reliability::reliable) {
  SegmentSpec s;
  s.name = "dds" + std::to_string(domain);
  s.type = SegmentType::dds;
  s.reliability = reliability;
  s.dds.domain = domain;
  return s;
}

ChannelBinding binding(ChannelId id, const std::string& name, HopRole role,
                       std::uint32_t omission_degree = 2) {
  ChannelBinding b;
  b.id = id;
  b.role = role;
  b.spec.name = name;
  b.spec.subject = 0x5100 + id;
  b.spec.omission_degree = omission_degree;
  b.spec.payload = 64;
  return b;
}

std::vector<std::string> peer(std::vector<std::string> args) {
  args.insert(args.begin(), COSMIC_DDS_PEER);
  return args;
}

std::uint8_t pattern(std::uint64_t q, std::uint64_t i) {
  return static_cast<std::uint8_t>((q * 7 + i) & 0xff);
}

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto b : bytes) {
    out.push_back(digits[b >> 4]);
    out.push_back(digits[b & 0xf]);
  }
  return out;
}

json parse(const std::string& line) { return json::parse(line, nullptr, false); }

// A stderr diagnostic line of the peer with the given "event".
std::function<bool(const std::string&)> diag_event(const std::string& event) {
  return [event](const std::string& line) {
    const json j = parse(line);
    return j.is_object() && j.value("event", "") == event;
  };
}
std::function<bool(const std::string&)> matched_at_least(int n) {
  return [n](const std::string& line) {
    const json j = parse(line);
    return j.is_object() && j.value("event", "") == "matched" && j.value("count", 0) >= n;
  };
}

// Spawns a peer publisher (with --start-on-stdin) and lets it publish once its writer matched
// and `ready` holds: our side matched it too (a reader drops what a writer sends before).
std::unique_ptr<Child> start_pub(std::vector<std::string> args,
                                 const std::function<bool()>& ready) {
  args.push_back("--start-on-stdin");
  auto pub = std::make_unique<Child>(peer(std::move(args)));
  EXPECT_TRUE(pub->wait_err(diag_event("waiting_for_start"), kWait)) << pub->describe();
  EXPECT_TRUE(test::eventually(ready, kWait)) << pub->describe();
  pub->send_line("go");
  return pub;
}

struct Fixture {
  explicit Fixture(SegmentSpec segment, std::uint64_t id = kSelfId)
      : spec(std::move(segment)),
        adapter(make_dds_segment_adapter(spec, GatewayIdentity{id, "gw-test"}, log)) {}
  test::StderrLogger log;
  SegmentSpec spec;
  RecordingSink sink;
  std::unique_ptr<DdsSegmentAdapter> adapter;

  bool matched(ChannelId id, HopRole role, std::size_t n = 1) {
    return test::eventually([&] { return adapter->matched_endpoints(id, role) >= n; }, kWait);
  }
  std::function<bool()> reader_matched(ChannelId id, std::size_t n = 1) {
    return [this, id, n] { return adapter->matched_endpoints(id, HopRole::publisher) >= n; };
  }
};

OutboundEvent outbound(ChannelId channel, std::uint32_t q, std::vector<std::uint8_t>& storage,
                       std::uint64_t origin = kSelfId, std::size_t size = 16) {
  storage.resize(size);
  for (std::size_t i = 0; i < size; ++i) storage[i] = pattern(q, i);
  OutboundEvent ev;
  ev.channel = channel;
  ev.header.subject = 0xABCDEF;
  ev.header.origin = origin;
  ev.header.sequence = q;
  ev.header.hop_count = 1;
  ev.header.created_ns = 1'000'000 + q;
  ev.header.age_ns = 1000 * q;
  ev.payload = storage;
  return ev;
}

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
  Child sub(peer({"sub", "--domain", "66", "--topic", "cosmic/log_nrt", "--count", "3", "--reliable",
                  "--timeout", "30"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();
  std::vector<std::uint8_t> storage;
  for (std::uint32_t q = 1; q <= 3; ++q) {
    ASSERT_EQ(f.adapter->send(outbound(2, q, storage)), SendStatus::sent);
  }
  ASSERT_EQ(sub.wait_exit(kWait), 0) << sub.describe();
  EXPECT_EQ(sub.out_lines().size(), 3u);
}

// ---- adapter -> native subscriber -------------------------------------------------------------

TEST(DdsAdapter, SendsEnvelopesToNativeSubscriber) {
  Fixture f(dds_segment(41));
  ASSERT_TRUE(f.adapter->start(f.sink).ok);
  EXPECT_EQ(f.adapter->health().state, SegmentHealth::up);
  const ChannelBinding b = binding(7, "robot.pose", HopRole::subscriber);
  ASSERT_TRUE(f.adapter->configure(std::span(&b, 1)).ok);

  constexpr int kCount = 50;
  Child sub(peer({"sub", "--domain", "41", "--topic", "cosmic/robot_pose", "--count",
                  std::to_string(kCount), "--reliable", "--timeout", "30"}));
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
  auto pub = start_pub({"pub", "--domain", "42", "--channel", "lidar.scan", "--count",
                        std::to_string(kCount), "--size", "24", "--subject", "99", "--origin",
                        "4242", "--hop-count", "2", "--age-ns", "777"},
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
  auto big = start_pub({"pub", "--domain", "48", "--channel", "big", "--count", "3", "--size",
                        "33"},
                       f.reader_matched(1));
  ASSERT_TRUE(f.sink.wait_problems(InboundProblem::decode_error, 3, kWait)) << big->describe();
  ASSERT_EQ(big->wait_exit(kWait), 0) << big->describe();
  ASSERT_TRUE(test::eventually([&] { return !f.reader_matched(1)(); }, kWait));
  auto small = start_pub({"pub", "--domain", "48", "--channel", "big", "--count", "2", "--size",
                          "32"},
                         f.reader_matched(1));
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
  const ChannelBinding both[] = {binding(5, "echo", HopRole::subscriber),
                                 binding(5, "echo", HopRole::publisher)};
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
  // ...A dropped all ten (same participant), B the five carrying its own origin.
  ASSERT_TRUE(a.sink.wait_problems(InboundProblem::own_echo, 10, kWait));
  ASSERT_TRUE(b.sink.wait_problems(InboundProblem::own_echo, 5, kWait));
  ASSERT_TRUE(b.sink.wait_count(5, 5, kWait));
  EXPECT_TRUE(a.sink.events().empty());
  for (const auto& e : b.sink.events()) {
    EXPECT_EQ(e.header.origin, 777u);
  }

  // A native publisher claiming this gateway's origin is dropped too.
  auto forged = start_pub({"pub", "--domain", "43", "--channel", "echo", "--count", "3",
                           "--size", "4", "--origin", std::to_string(kSelfId),
                           "--wait-subscribers", "2"},
                          [&] { return a.reader_matched(5, 2)() && b.reader_matched(5, 2)(); });
  ASSERT_TRUE(a.sink.wait_problems(InboundProblem::own_echo, 13, kWait)) << forged->describe();
  ASSERT_TRUE(b.sink.wait_problems(InboundProblem::own_echo, 8, kWait)) << forged->describe();
  ASSERT_EQ(forged->wait_exit(kWait), 0) << forged->describe();
  EXPECT_TRUE(a.sink.events().empty());
  EXPECT_EQ(b.sink.events().size(), 5u);
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

  Child sub(peer({"sub", "--domain", "44", "--channel", "imu", "--count", "0", "--timeout",
                  "30"}));
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

  Child reliable(peer({"sub", "--domain", "45", "--channel", "status", "--count", "1",
                       "--reliable", "--timeout", "30"}));
  Child best(peer({"sub", "--domain", "45", "--channel", "status", "--count", "1",
                   "--timeout", "30"}));
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
  Child sub(peer({"sub", "--domain", "60", "--channel", "map", "--count", "1", "--reliable",
                  "--transient-local", "--timeout", "30"}));
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
  const ChannelBinding bindings[] = {binding(6, "wheel", HopRole::publisher),
                                     binding(8, "other", HopRole::publisher)};
  ASSERT_TRUE(f.adapter->configure(bindings).ok);
  EXPECT_EQ(f.adapter->incompatible_peers(6), 0u);
  Child pub(peer({"pub", "--domain", "61", "--channel", "wheel", "--count", "1", "--size", "8",
                  "--best-effort", "--match-timeout", "30"}));
  ASSERT_TRUE(test::eventually([&] { return f.adapter->incompatible_peers(6) >= 1u; }, kWait))
      << pub.describe();
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
  auto pub = start_pub({"pub", "--domain", "62", "--channel", "wheel", "--count", "200", "--rate", "100",
                        "--size", "8", "--best-effort"},
                       f.reader_matched(6));
  ASSERT_TRUE(f.sink.wait_count(6, 1, kWait)) << pub->describe();
  EXPECT_EQ(f.adapter->incompatible_peers(6), 0u);
}

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
  const ChannelBinding clash[] = {binding(1, "keep", HopRole::subscriber),
                                  binding(2, "arm-left", HopRole::subscriber),
                                  binding(3, "arm.left", HopRole::publisher)};
  const Status st = f.adapter->configure(clash);
  ASSERT_FALSE(st.ok);
  EXPECT_NE(st.error.find("'arm-left'"), std::string::npos) << st.error;
  EXPECT_NE(st.error.find("'arm.left'"), std::string::npos) << st.error;
  EXPECT_NE(st.error.find("cosmic/arm_left"), std::string::npos) << st.error;
  // The running channel is untouched; one channel in both roles is no collision.
  Child sub(peer({"sub", "--domain", "63", "--channel", "keep", "--count", "1", "--timeout",
                  "30"}));
  ASSERT_TRUE(f.matched(1, HopRole::subscriber)) << sub.describe();
  const ChannelBinding both[] = {binding(1, "keep", HopRole::subscriber),
                                 binding(1, "keep", HopRole::publisher)};
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
  auto native = start_pub({"pub", "--domain", "64", "--channel", "native", "--count",
                           std::to_string(kCount), "--size", "8", "--origin", "0",
                           "--first-sequence", "1000"},
                          f.reader_matched(3));
  auto relayed = start_pub({"pub", "--domain", "64", "--channel", "relayed", "--count",
                            std::to_string(kCount), "--size", "8", "--origin", "77",
                            "--first-sequence", "1000"},
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
  Child sub(peer({"sub", "--domain", "46", "--channel", "out.flowing", "--count",
                  std::to_string(kCount), "--reliable", "--quiet", "--timeout", "60"}));
  ASSERT_TRUE(f.matched(2, HopRole::subscriber)) << sub.describe();
  ASSERT_TRUE(sub.wait_err(matched_at_least(1), kWait)) << sub.describe();
  auto pub = start_pub({"pub", "--domain", "46", "--channel", "in.flowing", "--count",
                        std::to_string(kCount), "--size", "8", "--rate", "400"},
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
  auto pub_added = start_pub({"pub", "--domain", "46", "--channel", "in.added", "--count", "5",
                              "--size", "8"},
                             f.reader_matched(3));
  ASSERT_TRUE(f.sink.wait_count(3, 5, kWait)) << pub_added->describe();
  Child sub_added(peer({"sub", "--domain", "46", "--channel", "out.added", "--count", "3",
                        "--reliable"}));
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
    auto pub = start_pub({"pub", "--domain", "47", "--channel", "removed.in", "--count", "5",
                          "--size", "4"},
                         f.reader_matched(2));
    ASSERT_TRUE(f.sink.wait_count(2, 5, kWait)) << pub->describe();
    ASSERT_EQ(pub->wait_exit(kWait), 0);
  }

  ASSERT_TRUE(f.adapter->configure(std::span(&kept, 1)).ok);
  EXPECT_EQ(f.adapter->matched_endpoints(2, HopRole::publisher), 0u);
  std::vector<std::uint8_t> storage;
  EXPECT_EQ(f.adapter->send(outbound(3, 1, storage)), SendStatus::failed);

  // On the DDS side nobody reads the removed channel any more...
  Child orphan(peer({"pub", "--domain", "47", "--channel", "removed.in", "--count", "5",
                     "--size", "4", "--match-timeout", "3"}));
  // ...while the kept channel still flows.
  auto pub = start_pub({"pub", "--domain", "47", "--channel", "kept", "--count", "20",
                        "--size", "4"},
                       f.reader_matched(1));
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
  Child sub(peer({"sub", "--domain", "52", "--channel", "odometry", "--count", "1", "--reliable",
                  "--timeout", "30"}));
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
  server_qos.wire_protocol().builtin.discovery_config.discoveryProtocol =
      rtps::DiscoveryProtocol_t::SERVER;
  eprosima::fastdds::rtps::get_server_client_default_guidPrefix(0,
                                                                server_qos.wire_protocol().prefix);
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
    const ChannelBinding dup[] = {binding(1, "x", HopRole::publisher),
                                  binding(1, "x", HopRole::publisher)};
    EXPECT_FALSE(adapter->configure(dup).ok);
    ChannelBinding nameless = binding(2, "", HopRole::subscriber);
    EXPECT_FALSE(adapter->configure(std::span(&nameless, 1)).ok);
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
    auto pub = start_pub({"pub", "--domain", std::to_string(domain), "--channel", "allowed",
                          "--count", "5", "--size", "4"},
                         f.reader_matched(1));
    ASSERT_TRUE(f.sink.wait_count(1, 5, kWait)) << pub->describe();
    EXPECT_EQ(pub->wait_exit(kWait), 0) << pub->describe();
  }
}

}  // namespace
}  // namespace cosmic

// Native DDS topics through the DDS adapter against real Fast DDS (issue 19, item 4): the
// serialized sample of any type crosses unchanged, a writer sends only bytes of the representation
// it announces, and the gateway never takes its own native writes back. Interoperability with an
// implementation we did not write (Cyclone DDS as a ROS 2 node) is tests/integration/dds/cyclone/
// ros2_interop_test.sh. Run inside a fresh network namespace; every test has its own domain.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <string>
#include <vector>

#include "cosmic/dds_adapter.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using test::RecordingSink;

constexpr auto kWait = 20s;
constexpr const char* kTwist = "geometry_msgs::msg::dds_::Twist_";

// Counts the log lines that contain `needle` (and passes every line to stderr).
class CountingLogger final : public Logger {
 public:
  explicit CountingLogger(std::string needle) : needle_(std::move(needle)) {}
  void log(LogLevel level, std::string_view message) override {
    if (message.find(needle_) != std::string_view::npos) count_.fetch_add(1);
    inner_.log(level, message);
  }
  int count() const { return count_.load(); }

 private:
  std::string needle_;
  std::atomic<int> count_{0};
  test::StderrLogger inner_;
};

SegmentSpec segment(std::uint32_t domain) {
  SegmentSpec s;
  s.name = "robot";
  s.type = SegmentType::dds;
  s.dds.domain = domain;
  return s;
}

ChannelBinding twist_binding(ChannelId id, HopRole role, DdsRepresentation representation = DdsRepresentation::xcdr1) {
  ChannelBinding b;
  b.id = id;
  b.role = role;
  b.spec.name = "cmd_vel";
  b.spec.subject = 0x300 + id;
  b.spec.cls = ChannelClass::srt;
  b.spec.payload = 52;
  b.spec.publishers = {"robot"};
  b.spec.subscribers = {"robot"};
  b.spec.native.push_back(
      NativeBinding{"robot", std::nullopt, std::nullopt, NativeDdsTopic{"rt/cmd_vel", kTwist, representation}});
  return b;
}

// A Twist as XCDR1 little-endian plain CDR (what ROS 2 writes): header 00 01 00 00, six doubles.
std::vector<std::uint8_t> twist_sample(double base, std::uint8_t encapsulation = 0x01) {
  std::vector<std::uint8_t> bytes{0x00, encapsulation, 0x00, 0x00};
  for (int i = 0; i < 6; ++i) {
    const double value = base + i * 0.5;
    std::uint8_t raw[8];
    std::memcpy(raw, &value, sizeof raw);
    bytes.insert(bytes.end(), raw, raw + sizeof raw);
  }
  return bytes;
}

OutboundEvent outbound(ChannelId channel, const std::vector<std::uint8_t>& bytes) {
  OutboundEvent ev;
  ev.channel = channel;
  ev.header.subject = 0x999;
  ev.header.origin = 0xABCD;  // a native sample carries none of this: it must not leak into the bytes
  ev.header.sequence = 77;
  ev.header.hop_count = 2;
  ev.payload = bytes;
  return ev;
}

struct Side {
  Side(std::uint32_t domain, std::uint64_t id, Logger& log)
      : spec(segment(domain)), adapter(make_dds_segment_adapter(spec, GatewayIdentity{id, "gw-native"}, log)) {}
  SegmentSpec spec;
  RecordingSink sink;
  std::unique_ptr<DdsSegmentAdapter> adapter;
  bool matched(ChannelId id, HopRole role, std::size_t n = 1) {
    return test::eventually([&] { return adapter->matched_endpoints(id, role) >= n; }, kWait);
  }
};

TEST(DdsNative, TheSerializedSampleCrossesUnchangedAndNumberedByItsWriter) {
  test::StderrLogger log;
  Side writer(61, 1, log);
  Side reader(61, 2, log);
  ASSERT_TRUE(writer.adapter->start(writer.sink).ok);
  ASSERT_TRUE(reader.adapter->start(reader.sink).ok);
  const ChannelBinding out = twist_binding(1, HopRole::subscriber);
  const ChannelBinding in = twist_binding(2, HopRole::publisher);
  ASSERT_TRUE(writer.adapter->configure(std::span(&out, 1)).ok);
  ASSERT_TRUE(reader.adapter->configure(std::span(&in, 1)).ok);
  ASSERT_TRUE(writer.matched(1, HopRole::subscriber));
  ASSERT_TRUE(reader.matched(2, HopRole::publisher));

  std::vector<std::vector<std::uint8_t>> sent;
  for (int q = 1; q <= 5; ++q) {
    sent.push_back(twist_sample(q));
    ASSERT_EQ(writer.adapter->send(outbound(1, sent.back())), SendStatus::sent);
  }
  ASSERT_TRUE(reader.sink.wait_count(2, 5, kWait));
  const auto events = reader.sink.events_on(2);
  for (std::size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(events[i].payload, sent[i]) << "sample " << i;
    EXPECT_EQ(events[i].header.origin, 0u) << "a native sample has no origin";
    EXPECT_EQ(events[i].header.sequence, i + 1) << "numbered by the writer's RTPS sequence";
    EXPECT_EQ(events[i].header.subject, in.spec.subject);
    EXPECT_EQ(events[i].header.hop_count, 0u);
  }
  EXPECT_EQ(writer.adapter->statistics().sent, 5u);
  EXPECT_EQ(*writer.adapter->incompatible_peers(1), 0u);
  EXPECT_EQ(*reader.adapter->incompatible_peers(2), 0u);
}

TEST(DdsNative, AWriterSendsOnlyBytesOfTheRepresentationItAnnounces) {
  CountingLogger log("is not a serialized geometry_msgs::msg::dds_::Twist_ sample for rt/cmd_vel");
  Side writer(62, 1, log);
  Side reader(62, 2, log);
  ASSERT_TRUE(writer.adapter->start(writer.sink).ok);
  ASSERT_TRUE(reader.adapter->start(reader.sink).ok);
  // An XCDR2 writer; the reader accepts both versions, so they match.
  const ChannelBinding out = twist_binding(1, HopRole::subscriber, DdsRepresentation::xcdr2);
  const ChannelBinding in = twist_binding(2, HopRole::publisher);
  ASSERT_TRUE(writer.adapter->configure(std::span(&out, 1)).ok);
  ASSERT_TRUE(reader.adapter->configure(std::span(&in, 1)).ok);
  ASSERT_TRUE(writer.matched(1, HopRole::subscriber));
  ASSERT_TRUE(reader.matched(2, HopRole::publisher));

  const std::vector<std::uint8_t> xcdr1 = twist_sample(1, 0x01);
  const std::vector<std::uint8_t> too_short{0x00, 0x07};
  const std::vector<std::uint8_t> xml = twist_sample(1, 0x04);
  const std::vector<std::uint8_t> xcdr2 = twist_sample(2, 0x07);
  EXPECT_EQ(writer.adapter->send(outbound(1, xcdr1)), SendStatus::failed);
  EXPECT_EQ(writer.adapter->send(outbound(1, too_short)), SendStatus::failed);
  EXPECT_EQ(writer.adapter->send(outbound(1, xml)), SendStatus::failed);
  EXPECT_EQ(writer.adapter->send(outbound(1, xcdr2)), SendStatus::sent);
  ASSERT_TRUE(reader.sink.wait_count(2, 1, kWait));
  EXPECT_EQ(reader.sink.events_on(2).at(0).payload, xcdr2);
  EXPECT_EQ(writer.adapter->statistics().send_errors, 3u);
  EXPECT_EQ(writer.adapter->statistics().sent, 1u);
  EXPECT_EQ(log.count(), 1) << "one log line per writer, not one per refused event";
}

TEST(DdsNative, TheGatewayNeverTakesItsOwnNativeWritesBack) {
  test::StderrLogger log;
  Side both(63, 1, log);
  Side other(63, 2, log);
  ASSERT_TRUE(both.adapter->start(both.sink).ok);
  ASSERT_TRUE(other.adapter->start(other.sink).ok);
  const ChannelBinding pair[] = {twist_binding(1, HopRole::subscriber), twist_binding(1, HopRole::publisher)};
  ASSERT_TRUE(both.adapter->configure(pair).ok);
  const ChannelBinding in = twist_binding(1, HopRole::publisher);
  ASSERT_TRUE(other.adapter->configure(std::span(&in, 1)).ok);
  ASSERT_TRUE(both.matched(1, HopRole::subscriber, 2));  // its own reader and the other's
  ASSERT_TRUE(both.matched(1, HopRole::publisher, 1));
  ASSERT_TRUE(other.matched(1, HopRole::publisher, 1));

  const std::vector<std::uint8_t> sample = twist_sample(3);
  for (int q = 0; q < 4; ++q) ASSERT_EQ(both.adapter->send(outbound(1, sample)), SendStatus::sent);
  // Identical bytes four times: all four reach the other gateway (no fingerprint guard on a
  // native DDS topic), none comes back to the writer's own reader.
  ASSERT_TRUE(other.sink.wait_count(1, 4, kWait));
  ASSERT_TRUE(both.sink.wait_problems(InboundProblem::own_echo, 4, kWait));
  EXPECT_TRUE(both.sink.events().empty());
}

}  // namespace
}  // namespace cosmic

// The identity of a component's events (issue 22, item 12): libcosmic-client stamps its own origin
// and a sequence per channel on DDS and on LCM alike, so a gateway receives (origin, sequence)
// pairs it can tell apart and keeps them end to end. Before, an LCM component's events carried its
// id while a DDS component's carried origin 0, which the first gateway renumbered as its own.
// The gateway side here is the gateway's own segment adapter; runs in a private network namespace.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/client.h"
#include "cosmic/dds_adapter.hpp"
#include "cosmic/lcm_adapter.hpp"

namespace {

using namespace std::chrono_literals;

constexpr cosmic_channel_desc kSpeed{"speed",    0x51, COSMIC_SRT, 10'000'000,    8'000'000,
                                     40'000'000, 1,    4,          COSMIC_PUBLISH};

class QuietLog : public cosmic::Logger {
 public:
  void log(cosmic::LogLevel, std::string_view) override {}
};

class HeaderSink : public cosmic::EventSink {
 public:
  void on_event(const cosmic::InboundEvent& event) override {
    std::lock_guard lock(mutex_);
    headers_.push_back(event.header);
    arrived_.notify_all();
  }
  void on_problem(cosmic::ChannelId, cosmic::InboundProblem) override {}
  bool wait_for(std::size_t n, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return arrived_.wait_for(lock, timeout, [&] { return headers_.size() >= n; });
  }
  std::vector<cosmic::EventHeader> headers() {
    std::lock_guard lock(mutex_);
    return headers_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<cosmic::EventHeader> headers_;
};

// The gateway's view of the channel a component announces with kSpeed (as libcosmic-client
// builds it from the descriptor).
cosmic::ChannelBinding gateway_binding() {
  cosmic::ChannelBinding b;
  b.id = 1;
  b.spec.name = kSpeed.name;
  b.spec.subject = kSpeed.subject;
  b.spec.cls = cosmic::ChannelClass::srt;
  b.spec.period = cosmic::Nanos(kSpeed.period_ns);
  b.spec.reaction_time = cosmic::Nanos(kSpeed.reaction_time_ns);
  b.spec.temp_validity = cosmic::Nanos(kSpeed.temp_validity_ns);
  b.spec.omission_degree = kSpeed.omission_degree;
  b.spec.payload = kSpeed.payload;
  b.role = cosmic::HopRole::publisher;  // the component publishes: the gateway receives
  return b;
}

void expect_component_identity(const char* component_segment, const cosmic::SegmentSpec& gateway_segment) {
  QuietLog log;
  HeaderSink sink;
  auto adapter = gateway_segment.type == cosmic::SegmentType::dds
                     ? cosmic::make_dds_adapter(gateway_segment, cosmic::GatewayIdentity{0x6A7E, "gw"}, log)
                     : cosmic::make_lcm_adapter(gateway_segment, cosmic::GatewayIdentity{0x6A7E, "gw"}, log);
  ASSERT_TRUE(adapter->start(sink).ok);
  const cosmic::ChannelBinding binding = gateway_binding();
  ASSERT_TRUE(adapter->configure(std::span(&binding, 1)).ok);

  char error[256] = "";
  cosmic_client* client = cosmic_open(component_segment, error, sizeof error);
  ASSERT_NE(client, nullptr) << error;
  cosmic_channel* out = cosmic_announce(client, &kSpeed, 1000);
  ASSERT_NE(out, nullptr) << cosmic_last_error(client);
  // Discovery takes its time: publish until two events arrived (deadline 20 s).
  const std::int32_t speed = 500;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!sink.wait_for(2, 20ms) && std::chrono::steady_clock::now() < deadline)
    cosmic_publish(out, &speed, sizeof speed);
  cosmic_close(client);
  adapter->stop();

  const auto headers = sink.headers();
  ASSERT_GE(headers.size(), 2u) << component_segment << ": no events within 20 s";
  EXPECT_NE(headers[0].origin, 0u) << component_segment << ": the component's own origin, not a native source's";
  EXPECT_NE(headers[0].origin, 0x6A7Eu);
  EXPECT_EQ(headers[1].origin, headers[0].origin);
  EXPECT_EQ(headers[1].sequence, headers[0].sequence + 1) << "the component's sequence, one per event";
  EXPECT_EQ(headers[0].subject, kSpeed.subject);
}

TEST(ClientIdentity, DdsComponentsStampTheirOwnOrigin) {
  cosmic::SegmentSpec dds;
  dds.name = "lan";
  dds.type = cosmic::SegmentType::dds;
  dds.dds.domain = 0;
  expect_component_identity("dds:0", dds);
}

TEST(ClientIdentity, LcmComponentsStampTheirOwnOrigin) {
  cosmic::SegmentSpec lcm;
  lcm.name = "tools";
  lcm.type = cosmic::SegmentType::lcm;
  lcm.lcm.url = "udpm://239.255.76.67:7791?ttl=0";
  expect_component_identity("lcm:udpm://239.255.76.67:7791?ttl=0", lcm);
}

// One client holding both roles of a channel (before, on LCM the two roles took two binding ids
// under one channel name and the announce failed): it receives another component's events, not
// its own.
void expect_both_roles(const char* segment) {
  char error[256] = "";
  cosmic_client* both = cosmic_open(segment, error, sizeof error);
  ASSERT_NE(both, nullptr) << error;
  cosmic_client* other = cosmic_open(segment, error, sizeof error);
  ASSERT_NE(other, nullptr) << error;
  cosmic_channel_desc desc = kSpeed;
  desc.roles = COSMIC_PUBLISH | COSMIC_SUBSCRIBE;
  cosmic_channel* mine = cosmic_announce(both, &desc, 1000);
  ASSERT_NE(mine, nullptr) << segment << ": " << cosmic_last_error(both);
  cosmic_channel* theirs = cosmic_announce(other, &kSpeed, 1000);
  ASSERT_NE(theirs, nullptr) << cosmic_last_error(other);
  const std::int32_t own = 1;
  const std::int32_t foreign = 2;
  cosmic_event_info info{};
  std::int32_t got = 0;
  int rc = COSMIC_E_AGAIN;
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (rc == COSMIC_E_AGAIN && std::chrono::steady_clock::now() < deadline) {
    EXPECT_EQ(cosmic_publish(mine, &own, sizeof own), COSMIC_OK);
    cosmic_publish(theirs, &foreign, sizeof foreign);
    std::this_thread::sleep_for(20ms);  // a poll period
    rc = cosmic_get_event(mine, &info, &got, sizeof got);
  }
  ASSERT_EQ(rc, COSMIC_OK) << segment << ": nothing received within 20 s";
  EXPECT_EQ(got, foreign) << segment << ": a client received its own event";
  while (cosmic_get_event(mine, &info, &got, sizeof got) == COSMIC_OK) EXPECT_EQ(got, foreign);
  cosmic_close(other);
  cosmic_close(both);
}

TEST(ClientIdentity, OneClientMayPublishAndSubscribeOneChannel) {
  expect_both_roles("dds:0");
  expect_both_roles("lcm:udpm://239.255.76.67:7792?ttl=0");
}

}  // namespace

// libcosmic-client through its C API: two components on one DDS domain (run in a private network
// namespace), polling with cosmic_get_event, the refusals of bad input, and the control query.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "cosmic/client.h"

namespace {

constexpr cosmic_channel_desc kSpeed{"speed", 0x51, COSMIC_SRT, 10'000'000, 8'000'000, 40'000'000, 1, 4, COSMIC_PUBLISH};

cosmic_channel_desc with_roles(cosmic_channel_desc d, int roles) {
  d.roles = roles;
  return d;
}

struct Client {
  explicit Client(const char* segment) : handle(cosmic_open(segment, error, sizeof error)) {}
  ~Client() { cosmic_close(handle); }
  char error[256] = "";
  cosmic_client* handle;
};

TEST(Client, RefusesBadSegmentsWithAReason) {
  for (const char* bad : {"", "dds", "dds:x", "dds:0?colour=red", "lcm:tcp://x", "can:vcan0", "can:vcan0?node=200", "zenoh:0"}) {
    Client c(bad);
    EXPECT_EQ(c.handle, nullptr) << bad;
    EXPECT_NE(std::string(c.error), "") << bad;
  }
}

TEST(Client, CanWithoutTheInterfaceFailsToOpen) {
  Client c("can:nosuchcan0?node=5");
  EXPECT_EQ(c.handle, nullptr);
  EXPECT_NE(std::string(c.error).find("nosuchcan0"), std::string::npos) << c.error;
}

TEST(Client, PollsWhatAnotherComponentPublishes) {
  Client pub("dds:0"), sub("dds:0");
  ASSERT_NE(pub.handle, nullptr) << pub.error;
  ASSERT_NE(sub.handle, nullptr) << sub.error;
  cosmic_channel* out = cosmic_announce(pub.handle, &kSpeed, 1000);
  const auto in_desc = with_roles(kSpeed, COSMIC_SUBSCRIBE);
  cosmic_channel* in = cosmic_announce(sub.handle, &in_desc, 1000);
  ASSERT_NE(out, nullptr) << cosmic_last_error(pub.handle);
  ASSERT_NE(in, nullptr) << cosmic_last_error(sub.handle);

  cosmic_event_info info{};
  std::uint8_t buffer[4];
  EXPECT_EQ(cosmic_get_event(in, &info, buffer, sizeof buffer), COSMIC_E_AGAIN);
  const std::uint8_t five[5] = {1, 2, 3, 4, 5};
  EXPECT_EQ(cosmic_publish(out, five, sizeof five), COSMIC_E_TOO_LARGE);
  EXPECT_NE(std::string(cosmic_last_error(pub.handle)).find("payload is 4 B"), std::string::npos);
  EXPECT_EQ(cosmic_publish(in, five, 4), COSMIC_E_INVALID);  // announced to subscribe only

  // Discovery takes its time: publish until the subscriber holds an event (deadline 20 s).
  const std::int32_t speed = 500;
  int rc = COSMIC_E_AGAIN;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (rc == COSMIC_E_AGAIN && std::chrono::steady_clock::now() < deadline) {
    cosmic_publish(out, &speed, sizeof speed);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a poll period, as a Simulink step
    std::uint8_t tiny[2];
    rc = cosmic_get_event(in, &info, tiny, sizeof tiny);
  }
  ASSERT_EQ(rc, COSMIC_E_TOO_LARGE) << "no event within 20 s";
  EXPECT_EQ(info.size, 4u);  // the event stays queued for a larger buffer
  ASSERT_EQ(cosmic_get_event(in, &info, buffer, sizeof buffer), COSMIC_OK);
  std::int32_t got = 0;
  std::memcpy(&got, buffer, sizeof got);
  EXPECT_EQ(got, 500);
  EXPECT_EQ(info.subject, 0x51u);
  EXPECT_GT(info.sequence, 0u);
}

TEST(Client, AnnounceRefusesIncompleteChannels) {
  Client c("dds:0");
  ASSERT_NE(c.handle, nullptr) << c.error;
  auto no_subject = kSpeed;
  no_subject.subject = 0;
  EXPECT_EQ(cosmic_announce(c.handle, &no_subject, 0), nullptr);
  EXPECT_NE(std::string(cosmic_last_error(c.handle)).find("subject"), std::string::npos);
  EXPECT_EQ(cosmic_announce(c.handle, &static_cast<const cosmic_channel_desc&>(with_roles(kSpeed, 0)), 0), nullptr);
}

TEST(Client, CheckChannelWithoutAGateway) {
  char verdict[128] = "";
  EXPECT_EQ(cosmic_check_channel("/nonexistent/cosmicd.sock", "speed", verdict, sizeof verdict), COSMIC_E_UNAVAILABLE);
  EXPECT_NE(std::string(verdict).find("/nonexistent/cosmicd.sock"), std::string::npos) << verdict;
}

}  // namespace

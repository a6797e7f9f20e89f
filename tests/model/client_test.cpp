// libcosmic-client through its C API: two components on one DDS domain (run in a private network
// namespace), polling with cosmic_get_event, waiting until a channel is carried (cosmic_wait_ready),
// the refusals of bad input, and the control query.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "cosmic/client.h"
#include "cosmic/client.hpp"

namespace {

constexpr cosmic_channel_desc kSpeed{"speed",    0x51, COSMIC_SRT, 10'000'000,    8'000'000,
                                     40'000'000, 1,    4,          COSMIC_PUBLISH};

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
  for (const char* bad :
       {"", "dds", "dds:x", "dds:0?colour=red", "lcm:tcp://x", "can:vcan0", "can:vcan0?node=200", "zenoh:0"}) {
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

// Publishes on `out` from its own thread until destroyed: the receive side is kept busy.
class Flood {
 public:
  explicit Flood(cosmic_channel* out)
      : thread_([this, out] {
          std::int32_t value = 0;
          while (!stop_) {
            cosmic_publish(out, &value, sizeof value);
            ++value;
            std::this_thread::sleep_for(std::chrono::microseconds(200));
          }
        }) {}
  ~Flood() {
    stop_ = true;
    thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

bool wait_for(const std::function<bool()>& done, std::chrono::milliseconds limit = std::chrono::seconds(20)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Work a callback does while the test may stop it: long enough to be caught in the middle.
void busy_for(std::chrono::microseconds d) {
  const auto until = std::chrono::steady_clock::now() + d;
  while (std::chrono::steady_clock::now() < until) {
  }
}

// What a callback sees of the test: counts calls, and calls that end after the test said "stopped".
struct Watch {
  std::atomic<int> calls{0};
  std::atomic<int> late{0};
  std::atomic<bool> stopped{false};
  void on_event() {
    ++calls;
    busy_for(std::chrono::microseconds(300));
    if (stopped) ++late;  // still running after unsubscribe returned: its state could be gone
  }
};

int queued_events(cosmic_channel* in) {
  int n = 0;
  cosmic_event_info info{};
  std::uint8_t buffer[4];
  while (cosmic_get_event(in, &info, buffer, sizeof buffer) == COSMIC_OK) ++n;
  return n;
}

// A publishing and a subscribing component of kSpeed on one DDS domain.
class ClientPair : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(pub.handle, nullptr) << pub.error;
    ASSERT_NE(sub.handle, nullptr) << sub.error;
    out = cosmic_announce(pub.handle, &kSpeed, 1000);
    const auto in_desc = with_roles(kSpeed, COSMIC_SUBSCRIBE);
    in = cosmic_announce(sub.handle, &in_desc, 1000);
    ASSERT_NE(out, nullptr);
    ASSERT_NE(in, nullptr);
  }
  Client pub{"dds:0"};
  Client sub{"dds:0"};
  cosmic_channel* out = nullptr;
  cosmic_channel* in = nullptr;
};

// Issue 18: a component must be able to stop its callbacks before the state they use goes.
TEST_F(ClientPair, UnsubscribeWaitsForARunningCallbackAndStopsIt) {
  Watch watch;
  ASSERT_EQ(cosmic_subscribe(
                in, [](const cosmic_event_info*, const std::uint8_t*, void* w) { static_cast<Watch*>(w)->on_event(); },
                &watch),
            COSMIC_OK);
  Flood flood(out);
  ASSERT_TRUE(wait_for([&] { return watch.calls >= 50; })) << "events did not reach the callback";
  ASSERT_EQ(cosmic_unsubscribe(in), COSMIC_OK);
  watch.stopped = true;
  const int calls_at_stop = watch.calls;
  // Events keep arriving, now into the queue, and the callback is never called again.
  int queued = 0;
  ASSERT_TRUE(wait_for([&] { return (queued += queued_events(in)) >= 20; })) << "events stopped arriving";
  EXPECT_EQ(watch.late, 0) << "a callback was still running when cosmic_unsubscribe returned";
  EXPECT_EQ(watch.calls, calls_at_stop);
  EXPECT_EQ(cosmic_unsubscribe(nullptr), COSMIC_E_INVALID);
}

TEST_F(ClientPair, ACallbackMayUnsubscribeItself) {
  struct Self {
    cosmic_channel* channel;
    std::atomic<int> calls{0};
  } self{in};
  ASSERT_EQ(cosmic_subscribe(
                in,
                [](const cosmic_event_info*, const std::uint8_t*, void* user) {
                  auto* s = static_cast<Self*>(user);
                  if (++s->calls == 3) cosmic_unsubscribe(s->channel);  // would deadlock on its own lock
                },
                &self),
            COSMIC_OK);
  Flood flood(out);
  int queued = 0;
  ASSERT_TRUE(wait_for([&] { return (queued += queued_events(in)) >= 10; }))
      << "events did not reach the queue after the stop";
  EXPECT_EQ(self.calls, 3);
}

// The C++ wrapper: a Subscription declared after the state its handler uses stops the handler
// before that state goes, even though the Client (declared first) is still receiving.
TEST(Client, ASubscriptionStopsItsHandlerBeforeTheStateItUsesGoes) {
  std::atomic<bool> state_gone{false};
  std::atomic<int> late{0};
  std::atomic<int> calls{0};
  struct State {
    std::atomic<bool>& gone;
    std::atomic<int>& calls;
    // Gives a handler that wrongly still runs the time to be called again (the flood sends every
    // 200 us): with the subscription gone first, no call comes and this waits its 200 ms out.
    ~State() {
      gone = true;
      const int before = calls;
      wait_for([&] { return calls > before + 1; }, std::chrono::milliseconds(200));
    }
  };
  cosmic::client::Client pub("dds:0");
  auto& out = pub.announce(kSpeed, 1000);
  Flood flood(out.handle());
  {
    cosmic::client::Client sub("dds:0");
    auto& in = sub.announce(with_roles(kSpeed, COSMIC_SUBSCRIBE), 1000);
    State state{state_gone, calls};
    auto subscription = in.on_event([&](const cosmic_event_info&, std::span<const std::uint8_t>) {
      ++calls;
      busy_for(std::chrono::microseconds(300));
      if (state.gone) ++late;
    });
    EXPECT_TRUE(subscription.active());
    ASSERT_TRUE(wait_for([&] { return calls >= 50; })) << "events did not reach the handler";
  }  // subscription, then state, then sub go: the handler never sees the state gone
  EXPECT_TRUE(state_gone);
  EXPECT_EQ(late, 0);
}

TEST(Client, ANewHandlerReplacesTheOldAndTheOldSubscriptionNoLongerStopsIt) {
  cosmic::client::Client pub("dds:0"), sub("dds:0");
  auto& out = pub.announce(kSpeed, 1000);
  auto& in = sub.announce(with_roles(kSpeed, COSMIC_SUBSCRIBE), 1000);
  std::atomic<int> first{0}, second{0};
  auto old = in.on_event([&](const cosmic_event_info&, std::span<const std::uint8_t>) { ++first; });
  Flood flood(out.handle());
  ASSERT_TRUE(wait_for([&] { return first > 0; }));
  auto now = in.on_event([&](const cosmic_event_info&, std::span<const std::uint8_t>) { ++second; });
  const int first_at_switch = first;
  EXPECT_FALSE(old.active());
  old.cancel();  // replaced already: must not stop the new handler
  ASSERT_TRUE(wait_for([&] { return second >= 10; })) << "the new handler stopped";
  EXPECT_EQ(first, first_at_switch);
  EXPECT_THROW((void)out.on_event([](const cosmic_event_info&, std::span<const std::uint8_t>) {}),
               std::invalid_argument);
  sub.close();  // stops every handler: the subscription outlives its client harmlessly
  EXPECT_FALSE(now.active());
  EXPECT_THROW(sub.announce(kSpeed, 0), std::runtime_error);
}

// Issue 40: a component waits until its channel is carried. A channel of its own name, so that no
// endpoint of another test can match it.
constexpr cosmic_channel_desc kProbe{"ready_probe", 0x4001, COSMIC_NRT, 0, 0, 0, 3, 4, COSMIC_PUBLISH};

std::chrono::milliseconds since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
}

TEST(Client, WaitReadyTimesOutWithoutAPeerAndReturnsOnceOneMatched) {
  Client pub("dds:0");
  ASSERT_NE(pub.handle, nullptr) << pub.error;
  cosmic_channel* out = cosmic_announce(pub.handle, &kProbe, 1000);
  ASSERT_NE(out, nullptr) << cosmic_last_error(pub.handle);

  // No reader anywhere: the timeout, with a reason naming the channel, segment, role and time.
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(cosmic_wait_ready(out, 200), COSMIC_E_TIMEOUT);
  EXPECT_GE(since(start), std::chrono::milliseconds(200)) << "returned before its timeout";
  const std::string why = cosmic_last_error(pub.handle);
  EXPECT_NE(why.find("channel 'ready_probe'"), std::string::npos) << why;
  EXPECT_NE(why.find("'dds:0'"), std::string::npos) << why;
  EXPECT_NE(why.find("publish (no reader"), std::string::npos) << why;
  EXPECT_EQ(why.find("subscribe"), std::string::npos) << why;
  const auto waited = why.find("after waiting ");
  ASSERT_NE(waited, std::string::npos) << why;
  EXPECT_GE(std::stoi(why.substr(waited + 14)), 200) << why;
  EXPECT_EQ(cosmic_wait_ready(out, 0), COSMIC_E_TIMEOUT);  // 0: a check without waiting

  // A second component subscribes: both sides become ready, well within the generous bound.
  Client sub("dds:0");
  ASSERT_NE(sub.handle, nullptr) << sub.error;
  const auto in_desc = with_roles(kProbe, COSMIC_SUBSCRIBE);
  cosmic_channel* in = cosmic_announce(sub.handle, &in_desc, 1000);
  ASSERT_NE(in, nullptr) << cosmic_last_error(sub.handle);
  start = std::chrono::steady_clock::now();
  ASSERT_EQ(cosmic_wait_ready(out, 10'000), COSMIC_OK) << cosmic_last_error(pub.handle);
  EXPECT_LT(since(start), std::chrono::milliseconds(10'000));
  ASSERT_EQ(cosmic_wait_ready(in, 10'000), COSMIC_OK) << cosmic_last_error(sub.handle);
  EXPECT_EQ(cosmic_wait_ready(out, 0), COSMIC_OK);  // stays ready while the peer is there

  // Once both ends are ready, the channel carries: the very first event arrives (no retries).
  const std::int32_t value = 7;
  ASSERT_EQ(cosmic_publish(out, &value, sizeof value), COSMIC_OK);
  cosmic_event_info info{};
  std::int32_t got = 0;
  EXPECT_TRUE(
      wait_for([&] { return cosmic_get_event(in, &info, &got, sizeof got) == COSMIC_OK; }, std::chrono::seconds(10)));
  EXPECT_EQ(got, 7);
}

TEST(Client, WaitReadyWithBothRolesNeedsAPeerNotItsOwnEndpoints) {
  Client both("dds:0");
  ASSERT_NE(both.handle, nullptr) << both.error;
  const auto desc = with_roles(kProbe, COSMIC_PUBLISH | COSMIC_SUBSCRIBE);
  cosmic_channel* ch = cosmic_announce(both.handle, &desc, 1000);
  ASSERT_NE(ch, nullptr) << cosmic_last_error(both.handle);
  // Its own reader matching its own writer carries nothing to or from the gateway.
  EXPECT_EQ(cosmic_wait_ready(ch, 300), COSMIC_E_TIMEOUT);
  const std::string why = cosmic_last_error(both.handle);
  EXPECT_NE(why.find("publish (no reader"), std::string::npos) << why;
  EXPECT_NE(why.find("subscribe (no writer"), std::string::npos) << why;

  Client peer("dds:0");  // publishes and subscribes too: matches both roles
  ASSERT_NE(peer.handle, nullptr) << peer.error;
  cosmic_channel* other = cosmic_announce(peer.handle, &desc, 1000);
  ASSERT_NE(other, nullptr) << cosmic_last_error(peer.handle);
  EXPECT_EQ(cosmic_wait_ready(ch, 10'000), COSMIC_OK) << cosmic_last_error(both.handle);
  EXPECT_EQ(cosmic_wait_ready(other, 10'000), COSMIC_OK) << cosmic_last_error(peer.handle);
}

TEST(Client, WaitReadyOnLcmReturnsAtOnceAndRefusesBadArguments) {
  Client lcm("lcm:udpm://239.255.76.67:7941?ttl=0");
  ASSERT_NE(lcm.handle, nullptr) << lcm.error;
  cosmic_channel* out = cosmic_announce(lcm.handle, &kProbe, 1000);
  ASSERT_NE(out, nullptr) << cosmic_last_error(lcm.handle);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(cosmic_wait_ready(out, 10'000), COSMIC_OK);  // no discovery: nothing to wait for
  EXPECT_LT(since(start), std::chrono::milliseconds(1000));
  EXPECT_EQ(cosmic_wait_ready(nullptr, 100), COSMIC_E_INVALID);
  EXPECT_EQ(cosmic_wait_ready(out, -1), COSMIC_E_INVALID);
  EXPECT_NE(std::string(cosmic_last_error(lcm.handle)).find("negative"), std::string::npos);
}

// The C++ wrapper: TimeoutError with the reason, then a return once a peer matched.
TEST(Client, WrapperWaitReadyThrowsTimeoutErrorUntilAPeerMatches) {
  cosmic::client::Client sub("dds:0");
  auto& in = sub.announce(with_roles(kProbe, COSMIC_SUBSCRIBE), 1000);
  try {
    in.wait_ready(std::chrono::milliseconds(100));
    ADD_FAILURE() << "ready without a writer";
  } catch (const cosmic::client::TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("subscribe (no writer"), std::string::npos) << e.what();
  }
  EXPECT_THROW(in.wait_ready(std::chrono::milliseconds(-1)), std::invalid_argument);
  cosmic::client::Client pub("dds:0");
  auto& out = pub.announce(kProbe, 1000);
  EXPECT_NO_THROW(in.wait_ready(std::chrono::seconds(10)));
  EXPECT_NO_THROW(out.wait_ready(std::chrono::seconds(10)));
}

TEST(Client, CheckChannelWithoutAGateway) {
  char verdict[128] = "";
  EXPECT_EQ(cosmic_check_channel("/nonexistent/cosmicd.sock", "speed", verdict, sizeof verdict), COSMIC_E_UNAVAILABLE);
  EXPECT_NE(std::string(verdict).find("/nonexistent/cosmicd.sock"), std::string::npos) << verdict;
}

}  // namespace

// Components on an authenticated LCM segment (docs/security.md): the key named in the segment's
// query is the client's; a component with it is heard, one without it never is.
namespace client_auth {

std::string write_client_key(const std::string& name, const std::string& hex, unsigned mode) {
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << hex << "\n";
  ::chmod(path.c_str(), mode);
  return path;
}

int poll_one(cosmic_channel* in, std::int32_t& value) {
  cosmic_event_info info{};
  return cosmic_get_event(in, &info, &value, sizeof value);
}

}  // namespace client_auth

TEST(Client, OnAnAuthenticatedLcmSegmentOnlyHoldersOfTheKeyAreHeard) {
  const std::string key = client_auth::write_client_key(
      "client_auth.key", "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff", 0600);
  const std::string other = client_auth::write_client_key(
      "client_other.key", "ffeeddccbbaa99887766554433221100ffeeddccbbaa99887766554433221100", 0600);
  const std::string url = "lcm:udpm://239.255.76.67:7942?ttl=0";
  Client sub((url + "&key_file=" + key + "&window=500ms").c_str());
  Client signer((url + "&key_file=" + key).c_str());
  Client stranger((url + "&key_file=" + other).c_str());
  Client plain(url.c_str());
  for (const Client* c : {&sub, &signer, &stranger, &plain}) ASSERT_NE(c->handle, nullptr) << c->error;
  const auto in_desc = with_roles(kSpeed, COSMIC_SUBSCRIBE);
  cosmic_channel* in = cosmic_announce(sub.handle, &in_desc, 1000);
  ASSERT_NE(in, nullptr) << cosmic_last_error(sub.handle);
  cosmic_channel* forged = cosmic_announce(stranger.handle, &kSpeed, 1000);
  cosmic_channel* unsigned_out = cosmic_announce(plain.handle, &kSpeed, 1000);
  cosmic_channel* out = cosmic_announce(signer.handle, &kSpeed, 1000);
  ASSERT_NE(forged, nullptr);
  ASSERT_NE(unsigned_out, nullptr);
  ASSERT_NE(out, nullptr);
  // The others publish first, then the holder of the key: the first event polled must be its own.
  const std::int32_t bad = -1;
  const std::int32_t good = 700;
  std::int32_t got = 0;
  int rc = COSMIC_E_AGAIN;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (rc == COSMIC_E_AGAIN && std::chrono::steady_clock::now() < deadline) {
    cosmic_publish(forged, &bad, sizeof bad);
    cosmic_publish(unsigned_out, &bad, sizeof bad);
    cosmic_publish(out, &good, sizeof good);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    rc = client_auth::poll_one(in, got);
  }
  ASSERT_EQ(rc, COSMIC_OK) << "no event within 20 s";
  EXPECT_EQ(got, good);
  // The path is up: the others publish once more, then the holder a last, distinct event. Everything
  // polled until that one arrives must be the holder's (the others' were sent before it).
  cosmic_publish(forged, &bad, sizeof bad);
  cosmic_publish(unsigned_out, &bad, sizeof bad);
  const std::int32_t last = 701;
  cosmic_publish(out, &last, sizeof last);
  const auto last_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (got != last && std::chrono::steady_clock::now() < last_deadline) {
    if (client_auth::poll_one(in, got) != COSMIC_OK) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    EXPECT_TRUE(got == good || got == last) << "an event without the key got through: " << got;
  }
  EXPECT_EQ(got, last) << "the holder's last event did not arrive";
}

TEST(Client, RefusesKeyFilesItCannotUseWithTheReason) {
  const std::string open_key = client_auth::write_client_key(
      "client_open.key", "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff", 0644);
  const std::string base = "lcm:udpm://239.255.76.67:7943?ttl=0";
  const struct {
    std::string segment;
    std::string reason;
  } cases[] = {
      {base + "&key_file=" + open_key, "group or others may read or write it"},
      {base + "&key_file=/nonexistent/lan.key", "cannot use key file /nonexistent/lan.key"},
      {base + "&window=1s", "window= and accept_key_file= need key_file="},
      {base + "&key_file=", "key_file= names no file"},
      {base + "&key_file=" + open_key + "&key_file=" + open_key, "key_file= is given twice"},
      {"lcm:memq://?key_file=" + open_key, "memq:// reaches no other program"},
  };
  for (const auto& c : cases) {
    Client client(c.segment.c_str());
    EXPECT_EQ(client.handle, nullptr) << c.segment;
    EXPECT_NE(std::string(client.error).find(c.reason), std::string::npos) << client.error;
  }
}

// Issue 20, item 2: no shared lock across I/O between classes. An NRT send stalled inside the
// kernel (a blocking sendmsg, as on a full socket buffer) must not delay an HRT send on the same
// segment. Before, every class published through one lcm_t under one encode mutex, so the HRT
// send waited for the stalled NRT one; now each class has its own transmit socket.
//
// The stall is real blocking inside the adapter's sendmsg: this executable defines sendmsg(),
// which the dynamic linker resolves the adapter's calls to (an executable's symbols come first);
// it passes every call to libc's sendmsg except, while armed, a message of the channel named
// kStalledChannel, which it holds until released.
#include <dlfcn.h>
#include <sys/socket.h>

#include <condition_variable>
#include <cstring>
#include <future>
#include <mutex>
#include <string_view>

#include "lcm_adapter_fixture.hpp"

namespace {

constexpr std::string_view kStalledChannel = "NRT_STALLED";

struct SendStall {
  std::mutex mutex;
  std::condition_variable changed;
  bool armed = false;
  bool holding = false;  // a sendmsg or sendmmsg of kStalledChannel is held
  unsigned batches = 0;  // sendmmsg calls so far
  unsigned batched = 0;  // messages they carried
};

SendStall& stall() {
  static SendStall instance;
  return instance;
}

bool carries_stalled_channel(const msghdr* msg) {
  for (std::size_t i = 0; i < msg->msg_iovlen; ++i) {
    const std::string_view part(static_cast<const char*>(msg->msg_iov[i].iov_base), msg->msg_iov[i].iov_len);
    if (part.find(kStalledChannel) != std::string_view::npos) return true;
  }
  return false;
}

// Holds the calling thread while armed (the caller carries kStalledChannel).
void hold_while_armed() {
  SendStall& s = stall();
  std::unique_lock lock(s.mutex);
  if (!s.armed) return;
  s.holding = true;
  s.changed.notify_all();
  s.changed.wait(lock, [&] { return !s.armed; });
  s.holding = false;
}

}  // namespace

extern "C" int sendmmsg(int fd, mmsghdr* msgs, unsigned int count, int flags) {
  using Real = int (*)(int, mmsghdr*, unsigned int, int);
  static const auto real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "sendmmsg"));
  bool stalled = false;
  for (unsigned i = 0; i < count; ++i) stalled = stalled || carries_stalled_channel(&msgs[i].msg_hdr);
  {
    std::lock_guard lock(stall().mutex);
    ++stall().batches;
    stall().batched += count;
  }
  if (stalled) hold_while_armed();
  return real(fd, msgs, count, flags);
}

extern "C" ssize_t sendmsg(int fd, const msghdr* msg, int flags) {
  using Real = ssize_t (*)(int, const msghdr*, int);
  static const auto real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "sendmsg"));
  if (carries_stalled_channel(msg)) hold_while_armed();
  return real(fd, msg, flags);
}

namespace cosmic::lcm_test {
namespace {

ChannelBinding class_binding(ChannelId id, const std::string& name, ChannelClass cls) {
  ChannelBinding b = binding(id, name, HopRole::subscriber);
  b.spec.cls = cls;
  return b;
}

TEST_F(LcmAdapterTest, AnNrtSendStalledInTheKernelDoesNotDelayAnHrtSend) {
  auto adapter = make(7712);
  ASSERT_TRUE(adapter->start(sink_).ok);
  const std::vector<ChannelBinding> bindings{class_binding(1, std::string(kStalledChannel), ChannelClass::nrt),
                                             class_binding(2, "HRT_FAST", ChannelClass::hrt),
                                             class_binding(3, "NRT_OTHER", ChannelClass::nrt)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  {
    std::lock_guard lock(stall().mutex);
    stall().armed = true;
  }
  const Bytes payload(64, 0x5A);
  auto nrt = std::async(std::launch::async, [&] { return adapter->send(outbound(1, payload, 1, 0, self_.id)); });
  {
    std::unique_lock lock(stall().mutex);
    ASSERT_TRUE(stall().changed.wait_for(lock, kWait, [] { return stall().holding; }))
        << "the NRT send never reached sendmsg";
  }
  // The NRT send is inside sendmsg now. An HRT send on the same segment completes regardless.
  auto hrt = std::async(std::launch::async, [&] { return adapter->send(outbound(2, payload, 1, 0, self_.id)); });
  const bool hrt_done = hrt.wait_for(kWait) == std::future_status::ready;
  {
    std::lock_guard lock(stall().mutex);
    stall().armed = false;
    stall().changed.notify_all();
  }
  ASSERT_TRUE(hrt_done) << "the HRT send waited for the stalled NRT send";
  EXPECT_EQ(hrt.get(), SendStatus::sent);
  EXPECT_EQ(nrt.get(), SendStatus::sent);
  // Within one class, sends still take turns: the other NRT channel goes once the stall ends.
  EXPECT_EQ(adapter->send(outbound(3, payload, 1, 0, self_.id)), SendStatus::sent);
  adapter->stop();
}

// The same through the egress lanes' batched path: an NRT batch stalled inside sendmmsg.
TEST_F(LcmAdapterTest, AnNrtBatchStalledInTheKernelDoesNotDelayAnHrtBatch) {
  auto adapter = make(7713);
  ASSERT_TRUE(adapter->start(sink_).ok);
  const std::vector<ChannelBinding> bindings{class_binding(1, std::string(kStalledChannel), ChannelClass::nrt),
                                             class_binding(2, "HRT_FAST", ChannelClass::hrt)};
  ASSERT_TRUE(adapter->configure(bindings).ok);
  {
    std::lock_guard lock(stall().mutex);
    stall().armed = true;
  }
  const Bytes payload(64, 0x5A);
  const std::vector<OutboundEvent> nrt_events(4, outbound(1, payload, 1, 0, self_.id));
  const std::vector<OutboundEvent> hrt_events(4, outbound(2, payload, 1, 0, self_.id));
  std::vector<SendStatus> nrt_results(4, SendStatus::failed);
  std::vector<SendStatus> hrt_results(4, SendStatus::failed);
  auto nrt = std::async(std::launch::async, [&] { adapter->send_batch(nrt_events, nrt_results); });
  {
    std::unique_lock lock(stall().mutex);
    ASSERT_TRUE(stall().changed.wait_for(lock, kWait, [] { return stall().holding; }))
        << "the NRT batch never reached sendmmsg";
  }
  auto hrt = std::async(std::launch::async, [&] { adapter->send_batch(hrt_events, hrt_results); });
  const bool hrt_done = hrt.wait_for(kWait) == std::future_status::ready;
  {
    std::lock_guard lock(stall().mutex);
    stall().armed = false;
    stall().changed.notify_all();
  }
  ASSERT_TRUE(hrt_done) << "the HRT batch waited for the stalled NRT batch";
  nrt.get();
  for (const SendStatus s : hrt_results) EXPECT_EQ(s, SendStatus::sent);
  for (const SendStatus s : nrt_results) EXPECT_EQ(s, SendStatus::sent);
  adapter->stop();
}

TEST_F(LcmAdapterTest, ABatchOfShortMessagesLeavesInOneSendmmsg) {
  auto adapter = make(7714);
  ASSERT_TRUE(adapter->start(sink_).ok);
  ASSERT_TRUE(adapter->configure(std::vector{class_binding(1, "NRT_MANY", ChannelClass::nrt)}).ok);
  const Bytes payload(64, 0x33);
  const std::vector<OutboundEvent> events(10, outbound(1, payload, 1, 0, self_.id));
  std::vector<SendStatus> results(10, SendStatus::failed);
  unsigned batches_before = 0;
  unsigned batched_before = 0;
  {
    std::lock_guard lock(stall().mutex);
    batches_before = stall().batches;
    batched_before = stall().batched;
  }
  adapter->send_batch(events, results);
  for (const SendStatus s : results) EXPECT_EQ(s, SendStatus::sent);
  {
    std::lock_guard lock(stall().mutex);
    EXPECT_EQ(stall().batches - batches_before, 1u);
    EXPECT_EQ(stall().batched - batched_before, 10u);
  }
  adapter->stop();
}

}  // namespace
}  // namespace cosmic::lcm_test

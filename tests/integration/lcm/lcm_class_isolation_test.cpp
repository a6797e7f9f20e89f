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
  bool holding = false;  // a sendmsg of kStalledChannel is held
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

}  // namespace

extern "C" ssize_t sendmsg(int fd, const msghdr* msg, int flags) {
  using Real = ssize_t (*)(int, const msghdr*, int);
  static const auto real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "sendmsg"));
  SendStall& s = stall();
  if (carries_stalled_channel(msg)) {
    std::unique_lock lock(s.mutex);
    if (s.armed) {
      s.holding = true;
      s.changed.notify_all();
      s.changed.wait(lock, [&] { return !s.armed; });
      s.holding = false;
    }
  }
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
    ASSERT_TRUE(stall().changed.wait_for(lock, kWait, [] { return stall().holding; })) << "the NRT send never reached sendmsg";
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

}  // namespace
}  // namespace cosmic::lcm_test

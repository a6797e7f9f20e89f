// Issue 20, item 2: no shared lock across I/O between classes. An NRT sender held up inside its
// write to the CAN socket (preempted there on a busy machine, or blocked) must not delay an HRT
// send on the same segment. Before, every send held the adapter's one I/O mutex across ::write,
// so the HRT send waited for the stalled NRT one.
//
// The stall is a real hold inside the write system call's place: this executable defines
// write(), which the adapter's calls resolve to (an executable's own definition wins); it passes
// every call to libc's write except, while armed, the write of a CAN frame with kStalledId,
// which it holds until released. Runs inside scripts/can-vm with the other CAN integration tests.
#include <dlfcn.h>
#include <linux/can.h>
#include <unistd.h>

#include <condition_variable>
#include <cstring>
#include <future>
#include <mutex>

#include <gtest/gtest.h>

#include "can_test_support.hpp"
#include "cosmic/can_adapter.hpp"
#include "cosmic/can_wire.hpp"

namespace {

struct WriteStall {
  std::mutex mutex;
  std::condition_variable changed;
  canid_t id = 0;  // the identifier (with CAN_EFF_FLAG) whose frame is held while armed
  bool armed = false;
  bool holding = false;
};

WriteStall& stall() {
  static WriteStall instance;
  return instance;
}

bool is_stalled_frame(const void* buffer, std::size_t count) {
  if (count != CAN_MTU && count != CANFD_MTU) return false;
  canid_t id = 0;
  std::memcpy(&id, buffer, sizeof id);
  std::lock_guard lock(stall().mutex);
  return stall().armed && id == stall().id;
}

}  // namespace

extern "C" ssize_t write(int fd, const void* buffer, std::size_t count) {
  using Real = ssize_t (*)(int, const void*, std::size_t);
  static const auto real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "write"));
  if (is_stalled_frame(buffer, count)) {
    WriteStall& s = stall();
    std::unique_lock lock(s.mutex);
    s.holding = true;
    s.changed.notify_all();
    s.changed.wait(lock, [&] { return !s.armed; });
    s.holding = false;
  }
  return real(fd, buffer, count);
}

namespace cosmic::test {
namespace {

constexpr milliseconds kIsolationWait{5000};

// Releases a held write however the test ends, so no sender stays blocked past it.
struct ReleaseOnExit {
  ~ReleaseOnExit() {
    std::lock_guard lock(stall().mutex);
    stall().armed = false;
    stall().changed.notify_all();
  }
};

TEST(CanClassIsolation, AnNrtSendHeldInsideItsWriteDoesNotDelayAnHrtSend) {
  ASSERT_EQ(shell("ip link set vcan0 up"), 0) << "needs vcan0: run through scripts/can-vm";
  RecordingSink sink;
  RecordingLogger log;
  const auto seg = can_segment("vcan0");
  auto adapter = make_can_adapter(seg, GatewayIdentity{7, "test-gw"}, log);
  ASSERT_TRUE(adapter->start(sink).ok);
  ChannelBinding nrt = can_binding(201, "nrt-bulk", 0x201, 8, HopRole::subscriber, 0xF0, 330, seg);
  nrt.spec.cls = ChannelClass::nrt;
  ChannelBinding hrt = can_binding(202, "hrt-brake", 0x202, 8, HopRole::subscriber, 0x00, 331, seg);
  hrt.spec.cls = ChannelClass::hrt;
  ASSERT_TRUE(adapter->configure(std::vector{nrt, hrt}).ok);
  ASSERT_TRUE(wait_until([&] { return adapter->health().state == SegmentHealth::up; }, kIsolationWait));
  const std::uint32_t nrt_id = encode_can_id(CanIdentifier{0xF0, kGatewayNode, 330});
  const std::uint32_t hrt_id = encode_can_id(CanIdentifier{0x00, kGatewayNode, 331});
  Candump dump("vcan0", "vcan0," + hex_id(hrt_id) + ":1FFFFFFF," + hex_id(nrt_id) + ":1FFFFFFF", 2);

  // The payloads outlive the sends (declared before the futures, whose destructors wait for them).
  const std::vector<std::uint8_t> bulk{0xB0};
  const std::vector<std::uint8_t> brake{0xA1};
  std::future<SendStatus> nrt_send;
  std::future<SendStatus> hrt_send;
  ReleaseOnExit release;  // destroyed before the futures, whose destructors wait for the sends
  {
    std::lock_guard lock(stall().mutex);
    stall().id = nrt_id | CAN_EFF_FLAG;
    stall().armed = true;
  }
  nrt_send = std::async(std::launch::async, [&] { return adapter->send(OutboundEvent{201, {}, bulk}); });
  bool held = false;  // asserted outside the lock: gtest's own output must not meet the interposer holding it
  {
    std::unique_lock lock(stall().mutex);
    held = stall().changed.wait_for(lock, kIsolationWait, [] { return stall().holding; });
  }
  ASSERT_TRUE(held) << "the NRT frame never reached write()";
  hrt_send = std::async(std::launch::async, [&] { return adapter->send(OutboundEvent{202, {}, brake}); });
  ASSERT_EQ(hrt_send.wait_for(kIsolationWait), std::future_status::ready)
      << "the HRT send waited for the held NRT write";
  EXPECT_EQ(hrt_send.get(), SendStatus::sent);
  EXPECT_TRUE(wait_until([&] { return !dump.lines().empty(); }, kIsolationWait));
  bool still_held = false;
  {
    std::lock_guard lock(stall().mutex);
    still_held = stall().holding;
    stall().armed = false;
    stall().changed.notify_all();
  }
  EXPECT_TRUE(still_held) << "the NRT write must still be held while the HRT frame goes out";
  EXPECT_EQ(nrt_send.get(), SendStatus::sent);
  const auto lines = dump.wait(kIsolationWait);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].id, hrt_id);  // on the bus first, though sent second
  EXPECT_EQ(lines[1].id, nrt_id);
  adapter->stop();
}

}  // namespace
}  // namespace cosmic::test

// The LCM transmit side (lcm_transmit.hpp) when the address its sockets send from goes away: the
// interface is renumbered under it, the next send fails, the socket is reopened on the new
// address and the datagrams carry that source from then on, which the receive filter follows.
// And its count of our own datagrams the receive filter drops.
// The network is a veth pair in this test's own namespace (scripts/netns-run); the kernel here
// has no dummy device.
#include <arpa/inet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "lcm_transmit.hpp"

namespace cosmic::lcm_detail {
namespace {

constexpr std::uint32_t kFirstAddress = 0x0a4d0001;   // 10.77.0.1
constexpr std::uint32_t kSecondAddress = 0x0a4d0002;  // 10.77.0.2

class LinesLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override {
    std::lock_guard lock(mutex_);
    lines_.emplace_back(message);
  }
  bool has(const std::string& part) {
    std::lock_guard lock(mutex_);
    for (const auto& line : lines_)
      if (line.find(part) != std::string::npos) return true;
    return false;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

int shell(const std::string& command) { return std::system((command + " 2>&1").c_str()); }

// A transmitter with what it reports to, and one raw 16-byte event of channel 1 (`name`) to send.
struct TransmitRig {
  explicit TransmitRig(const std::string& name) : transmitter(name, nullptr, log, counters, health, receive_failing) {
    channel.id = 1;
    channel.name = name;
    channel.format = make_lcm_message_format(LcmEncoding::raw);
    channel.tx = true;
    event.channel = 1;
    event.payload = payload;
  }
  SendStatus send() { return transmitter.send(channel, event); }

  LinesLogger log;
  AdapterCounters counters;
  HealthCell health;
  std::atomic<bool> receive_failing{false};
  LcmTransmitter transmitter;
  Channel channel;
  const std::vector<std::uint8_t> payload = std::vector<std::uint8_t>(16, 0x5a);
  OutboundEvent event;
};

// A member of the group on `interface` (by index, which renumbering keeps), bound to its port.
int group_member(const LcmUrl& url, const char* interface) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  const int on = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(url.port);
  ::inet_pton(AF_INET, url.group.c_str(), &at.sin_addr);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&at), sizeof at) != 0) return -1;
  ip_mreqn join{};
  join.imr_multiaddr = at.sin_addr;
  join.imr_ifindex = static_cast<int>(::if_nametoindex(interface));
  if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &join, sizeof join) != 0) return -1;
  return fd;
}

// The source of the next datagram on `fd` within `wait`.
std::optional<Endpoint> next_source(int fd, std::chrono::milliseconds wait) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) return std::nullopt;
  char bytes[65536];
  sockaddr_in from{};
  socklen_t length = sizeof from;
  if (::recvfrom(fd, bytes, sizeof bytes, 0, reinterpret_cast<sockaddr*>(&from), &length) < 0) return std::nullopt;
  return Endpoint{ntohl(from.sin_addr.s_addr), ntohs(from.sin_port)};
}

TEST(LcmTransmitReopen, ASocketWhoseAddressWentAwayIsReopenedOnTheNewOne) {
  // It changes the network: only in a namespace of its own (the suite runs under scripts/netns-run).
  const char* in_netns = std::getenv("COSMIC_IN_NETNS");
  ASSERT_TRUE(in_netns != nullptr && std::string(in_netns) == "1") << "run it under scripts/netns-run";
  ASSERT_EQ(shell("ip link add cosmic0 type veth peer name cosmic1 && ip link set cosmic1 up && "
                  "ip link set cosmic0 multicast on up && ip addr add 10.77.0.1/24 dev cosmic0 && "
                  "ip route add 239.255.77.0/24 dev cosmic0"),
            0);
  const auto parsed = parse_lcm_url("udpm://239.255.77.1:7701?ttl=0");
  ASSERT_TRUE(parsed.ok());
  const LcmUrl url = parsed.value();
  const int member = group_member(url, "cosmic0");
  ASSERT_GE(member, 0);
  // A receive socket as the adapter's, which the transmitter's filter follows.
  const OpenedSocket rx = open_receive_socket(url, 1 << 20);
  ASSERT_GE(rx.fd, 0) << rx.error;

  TransmitRig rig("RENUMBERED");
  LcmTransmitter& transmitter = rig.transmitter;
  ASSERT_TRUE(transmitter.open(url).ok());
  ASSERT_TRUE(transmitter.follow_with_filter(rx.fd, LcmOwnDatagrams::cut).ok());

  ASSERT_EQ(rig.send(), SendStatus::sent);
  const auto first = next_source(member, std::chrono::milliseconds(5000));
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->address, kFirstAddress);
  EXPECT_TRUE(transmitter.is_own(*first));

  // Renumbered: the old address goes, a new one comes (and the group's route with it).
  ASSERT_EQ(shell("ip addr del 10.77.0.1/24 dev cosmic0 && ip addr add 10.77.0.2/24 dev cosmic0 && "
                  "ip route replace 239.255.77.0/24 dev cosmic0"),
            0);
  // Sends fail until the socket is reopened (at once for the first failure, then at most once a
  // second); then they leave from the new address.
  std::optional<Endpoint> after;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(15);
  while (!after && std::chrono::steady_clock::now() < deadline) {
    if (rig.send() == SendStatus::sent) after = next_source(member, std::chrono::milliseconds(1000));
    if (!after) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(after.has_value()) << "no datagram from a reopened socket";
  EXPECT_EQ(after->address, kSecondAddress);
  EXPECT_TRUE(transmitter.is_own(*after));         // the receive side knows the new source as ours
  EXPECT_FALSE(transmitter.is_own(*first));        // and the old one no longer
  EXPECT_GE(rig.counters.send_errors.load(), 1u);  // the send that met the missing address
  EXPECT_TRUE(rig.log.has("transmit socket reopened"));
  // The receive socket's filter now cuts what the new source sends: its datagrams arrive empty.
  ASSERT_EQ(rig.send(), SendStatus::sent);
  std::optional<std::size_t> echo_size;
  ReceiveBatch batch(8);
  const auto echo_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!echo_size && std::chrono::steady_clock::now() < echo_deadline) {
    pollfd p{rx.fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int n = batch.receive(rx.fd);
    for (int i = 0; i < n; ++i) {
      if (batch.sender(static_cast<std::size_t>(i)) == *after)
        echo_size = batch.datagram(static_cast<std::size_t>(i)).size();
    }
  }
  ASSERT_TRUE(echo_size.has_value()) << "no echo of the new source on the receive socket";
  EXPECT_EQ(*echo_size, 0u);
  transmitter.close();
  ::close(member);
  ::close(rx.fd);
  EXPECT_EQ(shell("ip link del cosmic0"), 0);
}

// own_drops() counts what the receive socket's filter drops of ours: nothing while no filter
// could be attached or it only cuts, nothing while the receive socket is no member of the group.
TEST(LcmTransmitOwnDrops, CountedOnlyWhileAFilterDropsThemAndTheSocketIsAMember) {
  const auto parsed = parse_lcm_url("udpm://239.255.76.67:7714?ttl=0");
  ASSERT_TRUE(parsed.ok());
  const LcmUrl url = parsed.value();
  const OpenedSocket rx = open_receive_socket(url, 1 << 20);
  ASSERT_GE(rx.fd, 0) << rx.error;
  TransmitRig rig("OWN");
  LcmTransmitter& transmitter = rig.transmitter;
  ASSERT_TRUE(transmitter.open(url).ok());
  auto send = [&](int n) {
    for (int i = 0; i < n; ++i) ASSERT_EQ(rig.send(), SendStatus::sent);
  };

  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  EXPECT_FALSE(transmitter.follow_with_filter(pipe_fds[0], LcmOwnDatagrams::drop).ok());  // no socket
  send(2);
  EXPECT_EQ(transmitter.own_drops(), 0u);
  ASSERT_TRUE(transmitter.follow_with_filter(rx.fd, LcmOwnDatagrams::drop).ok());
  send(3);
  EXPECT_EQ(transmitter.own_drops(), 3u);
  transmitter.count_looped_back(false);  // the receive socket left the group
  send(2);
  EXPECT_EQ(transmitter.own_drops(), 3u);
  transmitter.count_looped_back(true);
  send(1);
  EXPECT_EQ(transmitter.own_drops(), 4u);
  ASSERT_TRUE(transmitter.follow_with_filter(rx.fd, LcmOwnDatagrams::cut).ok());
  send(1);
  EXPECT_EQ(transmitter.own_drops(), 4u);
  transmitter.close();
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
  ::close(rx.fd);
}

}  // namespace
}  // namespace cosmic::lcm_detail

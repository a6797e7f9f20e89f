// The LCM transport's socket layer (lcm_sockets.hpp) over real sockets, where the adapter's tests
// cannot reach: the receive filter cuts the datagrams of cosmicd's own transmit sockets and
// nothing else (a stranger that shares the port but not the address, and one that shares the
// address but not the port, get through whole), and the start-up self test says why when our
// own message does not come back.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <variant>

#include "lcm_sockets.hpp"

namespace cosmic::lcm_detail {
namespace {

constexpr std::uint32_t kLoopback = 0x7f000001;   // 127.0.0.1
constexpr std::uint32_t kLoopback2 = 0x7f000002;  // 127.0.0.2, also this host's (127/8 is lo)

struct Udp {
  int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ~Udp() {
    if (fd >= 0) ::close(fd);
  }
};

// Binds `s` to address:port (port 0: any), multicast out of lo; the endpoint it got.
Endpoint bind_sender(const Udp& s, std::uint32_t address, std::uint16_t port) {
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_addr.s_addr = htonl(address);
  at.sin_port = htons(port);
  if (::bind(s.fd, reinterpret_cast<const sockaddr*>(&at), sizeof at) != 0) return {};
  in_addr lo{};
  lo.s_addr = htonl(kLoopback);
  ::setsockopt(s.fd, IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo);
  sockaddr_in local{};
  socklen_t length = sizeof local;
  ::getsockname(s.fd, reinterpret_cast<sockaddr*>(&local), &length);
  return Endpoint{ntohl(local.sin_addr.s_addr), ntohs(local.sin_port)};
}

bool send_to_group(const Udp& s, const LcmUrl& url, std::size_t bytes) {
  sockaddr_in group{};
  group.sin_family = AF_INET;
  group.sin_port = htons(url.port);
  ::inet_pton(AF_INET, url.group.c_str(), &group.sin_addr);
  const std::string payload(bytes, 'x');
  return ::sendto(s.fd, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&group), sizeof group) ==
         static_cast<ssize_t>(bytes);
}

LcmUrl url_of(const char* text) { return parse_lcm_url(text).value(); }

TEST(LcmSocketFilter, CutsOnlyTheExactSourceOfOwnTransmitSockets) {
  const LcmUrl url = url_of("udpm://239.255.76.91:7691?ttl=0");
  const OpenedSocket rx = open_receive_socket(url, 1 << 20);
  ASSERT_GE(rx.fd, 0) << rx.error;

  Udp own, same_port, same_address;
  const Endpoint own_at = bind_sender(own, kLoopback, 0);
  ASSERT_NE(own_at.port, 0);
  const Endpoint same_port_at = bind_sender(same_port, kLoopback2, own_at.port);
  ASSERT_EQ(same_port_at.port, own_at.port) << "127.0.0.2 with the own port";
  const Endpoint same_address_at = bind_sender(same_address, kLoopback, 0);
  ASSERT_NE(same_address_at.port, own_at.port);

  const Endpoint filtered[] = {own_at};
  ASSERT_TRUE(drop_own_datagrams(rx.fd, filtered, LcmOwnDatagrams::cut).ok());
  ASSERT_TRUE(send_to_group(own, url, 10));
  ASSERT_TRUE(send_to_group(same_port, url, 20));
  ASSERT_TRUE(send_to_group(same_address, url, 30));

  std::map<std::uint64_t, std::size_t> size_by_sender;
  ReceiveBatch batch(8);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (size_by_sender.size() < 3 && std::chrono::steady_clock::now() < deadline) {
    pollfd p{rx.fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int n = batch.receive(rx.fd);
    for (int i = 0; i < n; ++i)
      size_by_sender[batch.sender(static_cast<std::size_t>(i)).key()] =
          batch.datagram(static_cast<std::size_t>(i)).size();
  }
  ::close(rx.fd);
  ASSERT_EQ(size_by_sender.size(), 3u);
  EXPECT_EQ(size_by_sender[own_at.key()], 0u);            // cut to its UDP header
  EXPECT_EQ(size_by_sender[same_port_at.key()], 20u);     // another address: whole
  EXPECT_EQ(size_by_sender[same_address_at.key()], 30u);  // another port: whole
}

// With the drop filter, the own datagram never reaches the queue: the others arrive whole, and
// the socket's drop count (SO_RXQ_OVFL, carried by the next datagram read) shows the one drop.
TEST(LcmSocketFilter, DropModeNeverQueuesOwnDatagramsAndTheKernelCountsThem) {
  const LcmUrl url = url_of("udpm://239.255.76.94:7695?ttl=0");
  const OpenedSocket rx = open_receive_socket(url, 1 << 20);
  ASSERT_GE(rx.fd, 0) << rx.error;
  Udp own, stranger;
  const Endpoint own_at = bind_sender(own, kLoopback, 0);
  const Endpoint stranger_at = bind_sender(stranger, kLoopback, 0);
  ASSERT_NE(own_at.port, 0);
  const Endpoint filtered[] = {own_at};
  ASSERT_TRUE(drop_own_datagrams(rx.fd, filtered, LcmOwnDatagrams::drop).ok());
  ASSERT_TRUE(send_to_group(own, url, 10));
  ASSERT_TRUE(send_to_group(stranger, url, 30));

  std::map<std::uint64_t, std::size_t> size_by_sender;
  std::optional<std::uint32_t> drops;
  ReceiveBatch batch(8);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (size_by_sender.empty() && std::chrono::steady_clock::now() < deadline) {
    pollfd p{rx.fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const int n = batch.receive(rx.fd);
    for (int i = 0; i < n; ++i)
      size_by_sender[batch.sender(static_cast<std::size_t>(i)).key()] =
          batch.datagram(static_cast<std::size_t>(i)).size();
    drops = batch.kernel_drops();
  }
  ::close(rx.fd);
  ASSERT_EQ(size_by_sender.size(), 1u);  // the stranger's, sent after ours: ours never arrived
  EXPECT_EQ(size_by_sender[stranger_at.key()], 30u);
  ASSERT_TRUE(drops.has_value());
  EXPECT_EQ(*drops, 1u);
}

TEST(LcmSelfTest, PassesWhenOurMessageComesBackToTheReceiveSocket) {
  const LcmUrl url = url_of("udpm://239.255.76.92:7692?ttl=0");
  const OpenedSocket rx = open_receive_socket(url, 1 << 20);
  ASSERT_GE(rx.fd, 0) << rx.error;
  EXPECT_TRUE(self_test(url, rx.fd, std::chrono::milliseconds(5000)).ok());
  ::close(rx.fd);
}

// The receive socket listens to another group's port, as one that the route, the loopback or a
// firewall keeps our message from: the self test waits its time and names the group and the
// likely causes.
TEST(LcmSelfTest, SaysWhyWhenOurMessageDoesNotComeBack) {
  const LcmUrl url = url_of("udpm://239.255.76.93:7693?ttl=0");
  const OpenedSocket elsewhere = open_receive_socket(url_of("udpm://239.255.76.93:7694?ttl=0"), 1 << 20);
  ASSERT_GE(elsewhere.fd, 0) << elsewhere.error;
  const Result<void> came_back = self_test(url, elsewhere.fd, std::chrono::milliseconds(300));
  ASSERT_FALSE(came_back.ok());
  const std::string& why = came_back.error().text;
  EXPECT_NE(why.find("239.255.76.93:7693 did not come back within 300 ms"), std::string::npos) << why;
  EXPECT_NE(why.find("multicast route"), std::string::npos) << why;
  ::close(elsewhere.fd);
}

}  // namespace
}  // namespace cosmic::lcm_detail

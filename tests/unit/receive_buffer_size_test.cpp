// The adapter kit's receive-buffer sizing (cosmic/receive_buffer_size.hpp) on a real UDP socket.
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <climits>
#include <fstream>
#include <string>

#include "cosmic/receive_buffer_size.hpp"

namespace cosmic {
namespace {

struct UdpSocket {
  int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ~UdpSocket() {
    if (fd >= 0) ::close(fd);
  }
};

// CAP_NET_ADMIN (bit 12) among this process's effective capabilities.
bool has_net_admin() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> 12) & 1;
  }
  return false;
}

int kernel_reports(int fd) {
  int value = 0;
  socklen_t length = sizeof value;
  return ::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &value, &length) == 0 ? value : -1;
}

TEST(ReceiveBufferSize, AsksTheKernelAndReportsWhatItGranted) {
  UdpSocket s;
  ASSERT_GE(s.fd, 0);
  // Far above Linux's default net.core.rmem_max (208 KiB): only SO_RCVBUFFORCE grants it.
  const ReceiveBufferSize size = size_receive_buffer(s.fd, 8 * 1024 * 1024);
  EXPECT_EQ(size.requested, 8 * 1024 * 1024);
  EXPECT_EQ(size.reported, kernel_reports(s.fd));  // what the socket really has
  EXPECT_EQ(size.usable(), size.reported / 2);
  EXPECT_EQ(size.short_of_request(), size.usable() < size.requested);
  // With CAP_NET_ADMIN (root in scripts/test and CI): the whole request, whatever rmem_max says.
  if (has_net_admin()) {
    EXPECT_FALSE(size.short_of_request()) << size.usable() << " of " << size.requested;
  }
}

TEST(ReceiveBufferSize, ClampsWhatNoIntCanHold) {
  UdpSocket s;
  ASSERT_GE(s.fd, 0);
  EXPECT_EQ(size_receive_buffer(s.fd, 1LL << 40).requested, INT_MAX / 2);
  EXPECT_EQ(size_receive_buffer(s.fd, -5).requested, 0);
}

TEST(ReceiveBufferSize, ABadSocketReportsNothingGranted) {
  const ReceiveBufferSize size = size_receive_buffer(-1, 4096);
  EXPECT_EQ(size.reported, 0);
  EXPECT_TRUE(size.short_of_request());
}

}  // namespace
}  // namespace cosmic

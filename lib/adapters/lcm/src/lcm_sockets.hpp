// The LCM adapter's own UDP multicast transport (the udpm wire format itself is
// cosmic/lcm_udpm.hpp): checked socket set-up, batched receive with kernel arrival times and the
// kernel's drop count, and the send of one message (one datagram or its fragments) with sendmsg.
// No liblcm: its reader thread and notification pipe cost two hand-offs and about five system
// calls per message (issue 20, item 5).
//
// Ownership: every function returns or takes plain descriptors; the caller closes them. A
// ReceiveBatch belongs to one thread (the segment's receive thread).
#pragma once

#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/lcm_udpm.hpp"
#include "cosmic/lcm_url.hpp"
#include "cosmic/result.hpp"
#include "cosmic/model.hpp"

namespace cosmic::lcm_detail {

// An IPv4 endpoint in host byte order; key() packs it for lookups.
struct Endpoint {
  std::uint32_t address = 0;
  std::uint16_t port = 0;
  std::uint64_t key() const { return (std::uint64_t{address} << 16) | port; }
  // "A.B.C.D:PORT", for log lines.
  std::string text() const {
    return std::to_string(address >> 24) + "." + std::to_string(address >> 16 & 255) + "." +
           std::to_string(address >> 8 & 255) + "." + std::to_string(address & 255) + ":" + std::to_string(port);
  }
  friend bool operator==(const Endpoint&, const Endpoint&) = default;
};

// A socket opened, or why not; warnings are set-up shortfalls it runs with regardless.
struct OpenedSocket {
  int fd = -1;
  Endpoint local;  // transmit sockets: the source every datagram of theirs carries
  std::string error;
  std::vector<std::string> warnings;
  // Receive sockets: IP_MULTICAST_ALL is off, so the socket gets only the groups it joined itself.
  bool sees_own_groups_only = false;
};

// Bound to the group's address and port (shared with other LCM programs on this host,
// SO_REUSEADDR), a member of the group on the default interface, receiving that group only
// (IP_MULTICAST_ALL off as well), non-blocking, with kernel arrival times (SO_TIMESTAMPNS) and drop counts
// (SO_RXQ_OVFL), and a receive buffer of `buffer_bytes` (SO_RCVBUFFORCE where privileged, else
// SO_RCVBUF up to net.core.rmem_max, with a warning when it falls short).
OpenedSocket open_receive_socket(const LcmUrl& url, std::size_t buffer_bytes);

// Connected to the group and port (the route and the source address are chosen once, and
// `local` names them), the URL's TTL (LCM's default 0 when it names none), loopback on so
// programs on this host receive what it sends.
OpenedSocket open_send_socket(const LcmUrl& url);

// Joins (`member`) or leaves the URL's group on receive socket `fd`, on the interface the kernel
// picks for it, as open_receive_socket() joined it. With IP_MULTICAST_ALL off, a socket that left
// receives nothing of the group, even while other sockets of the host stay members. An error says
// why not (joining and leaving twice fail).
Result<void> set_group_membership(int fd, const LcmUrl& url, bool member);

// Attaches a socket filter to receive socket `fd` that, in the kernel, cuts every datagram sent
// from one of `own` (our transmit sockets: multicast loopback hands our own datagrams back to
// every socket of the group, ours included) down to an empty one, so none of their bytes is
// copied, or with `mode` drop drops it before it is queued. Replaces a filter attached before.
// An error says why it is not attached. Either way the receive thread still tells them by their
// source.
Result<void> drop_own_datagrams(int fd, std::span<const Endpoint> own, LcmOwnDatagrams mode);

// liblcm's start-up check, as it makes it: a message on LCM_SELF_TEST sent from a socket of its
// own must come back to receive socket `fd` within `timeout`. Whatever else arrives meanwhile is
// read and dropped (nothing is delivered before the segment is up). An error when it did not come
// back says why not (no multicast loopback, a firewall, a route on another interface).
Result<void> self_test(const LcmUrl& url, int fd, std::chrono::milliseconds timeout);

// One recvmmsg's worth of datagrams, reused from call to call.
class ReceiveBatch {
 public:
  explicit ReceiveBatch(std::size_t slots);

  // Reads what is queued on `fd` without waiting: the number of datagrams (0 when none), or -1
  // with errno set.
  int receive(int fd);

  std::span<const std::uint8_t> datagram(std::size_t i) const;
  bool truncated(std::size_t i) const;  // longer than a slot: not LCM's (65,507 bytes at most)
  Endpoint sender(std::size_t i) const;
  std::int64_t arrival_realtime_ns(std::size_t i) const;  // 0 when the kernel gave none
  // The socket's count of datagrams dropped for a full buffer, as of the latest datagram that
  // carried it (SO_RXQ_OVFL); nullopt until one did.
  std::optional<std::uint32_t> kernel_drops() const { return kernel_drops_; }
  std::size_t slots() const { return headers_.size(); }

 private:
  struct Slot {
    std::vector<std::uint8_t> bytes;
    sockaddr_storage from{};
    alignas(cmsghdr) std::uint8_t control[128]{};
    std::int64_t arrival_ns = 0;
  };
  std::vector<Slot> slots_;
  std::vector<iovec> iovecs_;
  std::vector<mmsghdr> headers_;
  std::optional<std::uint32_t> kernel_drops_;
};

// Why a send failed, without allocating (sends run on the egress lanes): the errno (0 when the
// kernel gave none) and what failed; `what` null when nothing did.
struct SendFailure {
  int error = 0;
  const char* what = nullptr;
  bool failed() const { return what != nullptr; }
};

// Sends one LCM message whose payload is the concatenation of `parts` (at most
// SendBatch::kMaxParts) on connected socket `fd`: one short datagram, or its fragments back to
// back (cosmic/lcm_udpm.hpp). A message cut after some fragments is lost. Never allocates.
SendFailure send_lcm_message(int fd, std::uint32_t sequence, std::string_view channel,
                             std::span<const std::span<const std::uint8_t>> parts);

// Short messages (one datagram each) gathered for one sendmmsg on a connected socket: the system
// call and its entry cost once for a batch an egress lane hands over. Owned by one thread at a
// time (the sender of one class, under its mutex); the bytes of the parts must stay valid until
// send() returns.
class SendBatch {
 public:
  static constexpr std::size_t kCapacity = 32;
  static constexpr std::size_t kMaxParts = 3;  // a header, the contents, an authentication trailer

  // False when the batch is full or the message needs fragments (send it alone then).
  bool add(std::uint32_t sequence, std::string_view channel, std::span<const std::span<const std::uint8_t>> parts);
  std::size_t size() const { return count_; }
  // Sends every message added, in order, and empties the batch; `failed(i)` says whether the
  // i-th message did not go out whole, the result the first failure. Never allocates.
  SendFailure send(int fd);
  bool failed(std::size_t i) const { return failed_[i]; }

 private:
  struct Slot {
    std::array<std::uint8_t, kLcmShortHeaderSize> header{};
    std::array<char, kLcmMaxChannelBytes + 1> channel{};
    std::array<iovec, 2 + kMaxParts> iov{};
    std::size_t bytes = 0;
  };
  std::array<Slot, kCapacity> slots_{};
  std::array<mmsghdr, kCapacity> headers_{};
  std::array<bool, kCapacity> failed_{};
  std::size_t count_ = 0;
};

}  // namespace cosmic::lcm_detail

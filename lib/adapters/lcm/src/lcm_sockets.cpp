#include "lcm_sockets.hpp"

#include <arpa/inet.h>
#include <linux/filter.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cstring>

#include "cosmic/lcm_udpm.hpp"
#include "cosmic/result.hpp"
#include "cosmic/receive_buffer_size.hpp"

namespace cosmic::lcm_detail {
namespace {

// "WHAT: <errno text>" for the call that just failed.
std::string failed_call(const char* what) { return Error::from_errno(what, errno).text; }

// The group and port as a socket address; nullopt when the group is not an IPv4 address.
std::optional<sockaddr_in> group_address(const LcmUrl& url) {
  sockaddr_in out{};
  out.sin_family = AF_INET;
  out.sin_port = htons(url.port);
  if (::inet_pton(AF_INET, url.group.c_str(), &out.sin_addr) != 1) return std::nullopt;
  return out;
}

int set_int(int fd, int level, int name, int value) { return ::setsockopt(fd, level, name, &value, sizeof value); }

// The socket's receive buffer as close to `bytes` as this process may make it; a warning when
// it falls short.
void warn_if_short(int fd, std::size_t bytes, OpenedSocket& out) {
  const ReceiveBufferSize size = size_receive_buffer(fd, static_cast<long long>(std::min<std::size_t>(bytes, INT_MAX)));
  if (size.reported == 0 || !size.short_of_request()) return;
  out.warnings.push_back("the receive buffer holds " + std::to_string(size.usable()) + " bytes, not the " +
                         std::to_string(size.requested) +
                         " asked for: a burst beyond it is lost (counted as overflow "
                         "drops). Set net.core.rmem_max to at least " +
                         std::to_string(size.requested) + " or give cosmicd CAP_NET_ADMIN");
}

OpenedSocket failed(OpenedSocket out, int fd, std::string why) {
  if (fd >= 0) ::close(fd);
  out.fd = -1;
  out.error = std::move(why);
  return out;
}

}  // namespace

OpenedSocket open_receive_socket(const LcmUrl& url, std::size_t buffer_bytes) {
  OpenedSocket out;
  const auto group = group_address(url);
  if (!group) return failed(std::move(out), -1, "not an IPv4 multicast group: " + url.group);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return failed(std::move(out), fd, failed_call("socket"));
  if (set_int(fd, SOL_SOCKET, SO_REUSEADDR, 1) != 0) return failed(std::move(out), fd, failed_call("SO_REUSEADDR"));
  sockaddr_in bind_to{};
  bind_to.sin_family = AF_INET;
  bind_to.sin_port = htons(url.port);
  // The group's address, not every address: a unicast datagram to this host's port is no
  // message of the group (as liblcm binds on Linux).
  bind_to.sin_addr = group->sin_addr;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&bind_to), sizeof bind_to) != 0)
    return failed(std::move(out), fd, failed_call(("bind to port " + std::to_string(url.port)).c_str()));
  if (Result<void> joined = set_group_membership(fd, url, true); !joined)
    return failed(std::move(out), fd, std::move(joined).error().text);
  // Without this, Linux hands the socket every group any socket of the host joined on this port.
  if (set_int(fd, IPPROTO_IP, IP_MULTICAST_ALL, 0) != 0)
    out.warnings.push_back(failed_call("IP_MULTICAST_ALL"));
  else
    out.sees_own_groups_only = true;
  if (set_int(fd, SOL_SOCKET, SO_TIMESTAMPNS, 1) != 0)
    out.warnings.push_back(failed_call("SO_TIMESTAMPNS (residence then starts when the datagram is read)"));
  if (set_int(fd, SOL_SOCKET, SO_RXQ_OVFL, 1) != 0)
    out.warnings.push_back(failed_call("SO_RXQ_OVFL (drops not counted)"));
  warn_if_short(fd, url.recv_buf_size ? *url.recv_buf_size : buffer_bytes, out);
  out.fd = fd;
  return out;
}

Result<void> set_group_membership(int fd, const LcmUrl& url, bool member) {
  const auto group = group_address(url);
  if (!group) return Error{"not an IPv4 multicast group: " + url.group};
  ip_mreq membership{};
  membership.imr_multiaddr = group->sin_addr;
  membership.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(fd, IPPROTO_IP, member ? IP_ADD_MEMBERSHIP : IP_DROP_MEMBERSHIP, &membership, sizeof membership) ==
      0)
    return {};
  return Error::from_errno(member ? "joining " + url.group + " (check the multicast route)" : "leaving " + url.group,
                           errno);
}

OpenedSocket open_send_socket(const LcmUrl& url) {
  OpenedSocket out;
  const auto group = group_address(url);
  if (!group) return failed(std::move(out), -1, "not an IPv4 multicast group: " + url.group);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return failed(std::move(out), fd, failed_call("socket"));
  const int ttl = static_cast<int>(url.ttl.value_or(0));
  if (set_int(fd, IPPROTO_IP, IP_MULTICAST_TTL, ttl) != 0)
    return failed(std::move(out), fd, failed_call("IP_MULTICAST_TTL"));
  if (set_int(fd, IPPROTO_IP, IP_MULTICAST_LOOP, 1) != 0)
    return failed(std::move(out), fd, failed_call("IP_MULTICAST_LOOP"));
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&*group), sizeof *group) != 0)
    return failed(std::move(out), fd,
                  failed_call(("no route to " + url.group + " (check the multicast route)").c_str()));
  sockaddr_in local{};
  socklen_t length = sizeof local;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) != 0)
    return failed(std::move(out), fd, failed_call("getsockname"));
  out.local = Endpoint{ntohl(local.sin_addr.s_addr), ntohs(local.sin_port)};
  out.fd = fd;
  return out;
}

// Classic BPF over a UDP socket's datagram: the filter runs with the UDP header at offset 0 and
// the IP header at SKF_NET_OFF. Per own endpoint: source address, then source port; a match keeps
// the UDP header alone (the kernel trims to at least that), or nothing (dropped); anything else
// is accepted whole. Dropping (the default) spares the receive thread a wake-up and a read per
// datagram sent; a dropped datagram counts in the socket's drops (SO_RXQ_OVFL) and in the host's
// UDP InErrors, which cutting leaves alone.
Result<void> drop_own_datagrams(int fd, std::span<const Endpoint> own, LcmOwnDatagrams mode) {
  constexpr std::uint32_t kSourceAddress = static_cast<std::uint32_t>(SKF_NET_OFF) + 12;
  constexpr std::uint32_t kSourcePort = 0;
  if (own.empty() || own.size() > 16) return Error{"no endpoints to filter"};
  std::vector<sock_filter> program;
  const std::size_t drop_at = own.size() * 4 + 1;  // the trim: after every check and the accept
  for (const Endpoint& e : own) {
    program.push_back(BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kSourceAddress));
    program.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, e.address, 0, 2));
    program.push_back(BPF_STMT(BPF_LD | BPF_H | BPF_ABS, kSourcePort));
    const std::size_t here = program.size();
    program.push_back(BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, e.port, static_cast<std::uint8_t>(drop_at - here - 1), 0));
  }
  program.push_back(BPF_STMT(BPF_RET | BPF_K, 0xFFFFFFFFu));  // accept
  // Cut: trim to the UDP header (queued, read, skipped). Drop: 0, never queued.
  program.push_back(BPF_STMT(BPF_RET | BPF_K, mode == LcmOwnDatagrams::drop ? 0u : 1u));
  const sock_fprog fprog{static_cast<unsigned short>(program.size()), program.data()};
  if (::setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0)
    return Error::from_errno("SO_ATTACH_FILTER", errno);
  return {};
}

Result<void> self_test(const LcmUrl& url, int fd, std::chrono::milliseconds timeout) {
  static constexpr std::string_view kChannel = "LCM_SELF_TEST";
  OpenedSocket probe = open_send_socket(url);
  if (probe.fd < 0) return Error{"self test: " + probe.error};
  // A payload no other sender's message carries: our probe socket's own source.
  std::array<std::uint8_t, 6> token{};
  const std::uint64_t key = probe.local.key();
  for (std::size_t i = 0; i < token.size(); ++i) token[i] = static_cast<std::uint8_t>(key >> (8 * i));
  const std::array<std::span<const std::uint8_t>, 1> parts{std::span<const std::uint8_t>(token)};
  const SendFailure sent = send_lcm_message(probe.fd, 0, kChannel, parts);
  ::close(probe.fd);
  if (sent.failed()) {
    return Error{std::string("self test: ") + sent.what + (sent.error ? ": " + errno_text(sent.error) : ""),
                 sent.error};
  }
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  ReceiveBatch batch(8);
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    const int n = batch.receive(fd);
    if (n < 0) return Error::from_errno("self test: recvmmsg", errno);
    for (int i = 0; i < n; ++i) {
      const auto d = parse_lcm_datagram(batch.datagram(static_cast<std::size_t>(i)));
      if (d && !d->fragment && d->channel == kChannel && batch.sender(static_cast<std::size_t>(i)) == probe.local &&
          std::equal(d->data.begin(), d->data.end(), token.begin(), token.end()))
        return {};
    }
  }
  return Error{"self test: our own message on " + url.group + ":" + std::to_string(url.port) +
               " did not come back within " + std::to_string(timeout.count()) +
               " ms (check the multicast route, multicast loopback and the firewall)"};
}

ReceiveBatch::ReceiveBatch(std::size_t slots) : slots_(slots), iovecs_(slots), headers_(slots) {
  for (std::size_t i = 0; i < slots; ++i) {
    // One byte beyond the largest LCM datagram: a longer one shows as truncated.
    slots_[i].bytes.resize(kLcmMaxDatagram + 1);
    iovecs_[i] = iovec{slots_[i].bytes.data(), slots_[i].bytes.size()};
  }
}

int ReceiveBatch::receive(int fd) {
  for (std::size_t i = 0; i < headers_.size(); ++i) {
    msghdr& h = headers_[i].msg_hdr;
    h = msghdr{};
    h.msg_name = &slots_[i].from;
    h.msg_namelen = sizeof slots_[i].from;
    h.msg_iov = &iovecs_[i];
    h.msg_iovlen = 1;
    h.msg_control = slots_[i].control;
    h.msg_controllen = sizeof slots_[i].control;
    headers_[i].msg_len = 0;
  }
  const int n = ::recvmmsg(fd, headers_.data(), static_cast<unsigned>(headers_.size()), MSG_DONTWAIT, nullptr);
  if (n < 0) return (errno == EAGAIN || errno == EWOULDBLOCK) ? 0 : -1;
  for (int i = 0; i < n; ++i) {
    Slot& slot = slots_[static_cast<std::size_t>(i)];
    slot.arrival_ns = 0;
    msghdr& h = headers_[static_cast<std::size_t>(i)].msg_hdr;
    for (cmsghdr* c = CMSG_FIRSTHDR(&h); c != nullptr; c = CMSG_NXTHDR(&h, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec ts{};
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        slot.arrival_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t drops = 0;
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        kernel_drops_ = drops;
      }
    }
  }
  return n;
}

std::span<const std::uint8_t> ReceiveBatch::datagram(std::size_t i) const {
  return std::span<const std::uint8_t>(slots_[i].bytes.data(),
                                       std::min<std::size_t>(headers_[i].msg_len, kLcmMaxDatagram));
}

bool ReceiveBatch::truncated(std::size_t i) const {
  return (headers_[i].msg_hdr.msg_flags & MSG_TRUNC) != 0 || headers_[i].msg_len > kLcmMaxDatagram;
}

Endpoint ReceiveBatch::sender(std::size_t i) const {
  const auto& from = slots_[i].from;
  if (from.ss_family != AF_INET) return Endpoint{};
  sockaddr_in in{};
  std::memcpy(&in, &from, sizeof in);
  return Endpoint{ntohl(in.sin_addr.s_addr), ntohs(in.sin_port)};
}

std::int64_t ReceiveBatch::arrival_realtime_ns(std::size_t i) const { return slots_[i].arrival_ns; }

namespace {

constexpr std::size_t kMaxIov = 2 + SendBatch::kMaxParts;  // header, channel, the payload's parts

// The iovecs of payload bytes [offset, offset + length) of the concatenated `parts`, appended
// after the `count` already in `iov`; the new count.
std::size_t append_slice(std::span<const std::span<const std::uint8_t>> parts, std::size_t offset, std::size_t length,
                         std::array<iovec, kMaxIov>& iov, std::size_t count) {
  for (const auto& part : parts) {
    if (length == 0) break;
    if (offset >= part.size()) {
      offset -= part.size();
      continue;
    }
    const std::size_t take = std::min(length, part.size() - offset);
    iov[count++] = iovec{const_cast<std::uint8_t*>(part.data() + offset), take};  // the kernel only reads it
    length -= take;
    offset = 0;
  }
  return count;
}

SendFailure send_datagram(int fd, std::array<iovec, kMaxIov>& iov, std::size_t count) {
  std::size_t expected = 0;
  for (std::size_t i = 0; i < count; ++i) expected += iov[i].iov_len;
  msghdr msg{};
  msg.msg_iov = iov.data();
  msg.msg_iovlen = count;
  ssize_t n = -1;
  do {
    n = ::sendmsg(fd, &msg, MSG_NOSIGNAL);
  } while (n < 0 && errno == EINTR);
  if (n < 0) return SendFailure{errno, "sendmsg"};
  if (static_cast<std::size_t>(n) != expected) return SendFailure{0, "sendmsg sent part of a datagram"};
  return SendFailure{};
}

}  // namespace

SendFailure send_lcm_message(int fd, std::uint32_t sequence, std::string_view channel,
                             std::span<const std::span<const std::uint8_t>> parts) {
  if (parts.size() > SendBatch::kMaxParts) return SendFailure{0, "too many parts"};
  std::size_t payload_size = 0;
  for (const auto& part : parts) payload_size += part.size();
  const auto plan = plan_lcm_message(channel.size(), payload_size);
  if (!plan) return SendFailure{0, "message too large for LCM (more than 65,535 fragments)"};
  // The channel with its NUL: string_view does not promise one, so it is sent from here.
  std::array<char, kLcmMaxChannelBytes + 1> name{};
  std::memcpy(name.data(), channel.data(), channel.size());
  std::array<iovec, kMaxIov> iov{};
  if (plan->fragment_count == 0) {
    auto header = lcm_short_header(sequence);
    iov[0] = iovec{header.data(), header.size()};
    iov[1] = iovec{name.data(), channel.size() + 1};
    return send_datagram(fd, iov, append_slice(parts, 0, payload_size, iov, 2));
  }
  std::size_t offset = 0;
  for (std::uint16_t no = 0; no < plan->fragment_count; ++no) {
    const std::size_t slice = std::min(payload_size - offset, no == 0 ? plan->first_slice : kLcmFragmentMaxData);
    auto header = lcm_fragment_header(sequence, static_cast<std::uint32_t>(payload_size),
                                      static_cast<std::uint32_t>(offset), no, plan->fragment_count);
    std::size_t count = 0;
    iov[count++] = iovec{header.data(), header.size()};
    if (no == 0) iov[count++] = iovec{name.data(), channel.size() + 1};
    count = append_slice(parts, offset, slice, iov, count);
    if (const SendFailure failure = send_datagram(fd, iov, count); failure.failed()) return failure;
    offset += slice;
  }
  return SendFailure{};
}

bool SendBatch::add(std::uint32_t sequence, std::string_view channel,
                    std::span<const std::span<const std::uint8_t>> parts) {
  if (count_ == kCapacity || parts.size() > kMaxParts) return false;
  std::size_t payload_size = 0;
  for (const auto& part : parts) payload_size += part.size();
  const auto plan = plan_lcm_message(channel.size(), payload_size);
  if (!plan || plan->fragment_count != 0) return false;
  Slot& slot = slots_[count_];
  slot.header = lcm_short_header(sequence);
  std::memcpy(slot.channel.data(), channel.data(), channel.size());
  slot.channel[channel.size()] = '\0';
  std::size_t n = 0;
  slot.iov[n++] = iovec{slot.header.data(), slot.header.size()};
  slot.iov[n++] = iovec{slot.channel.data(), channel.size() + 1};
  for (const auto& part : parts)
    if (!part.empty()) slot.iov[n++] = iovec{const_cast<std::uint8_t*>(part.data()), part.size()};
  slot.bytes = kLcmShortHeaderSize + channel.size() + 1 + payload_size;
  mmsghdr& h = headers_[count_];
  h = mmsghdr{};
  h.msg_hdr.msg_iov = slot.iov.data();
  h.msg_hdr.msg_iovlen = n;
  failed_[count_] = false;
  ++count_;
  return true;
}

SendFailure SendBatch::send(int fd) {
  SendFailure first;
  std::size_t done = 0;
  while (done < count_) {
    const int n = ::sendmmsg(fd, headers_.data() + done, static_cast<unsigned>(count_ - done), MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      // The first message of the rest failed (errno): mark it and go on with the others.
      if (!first.failed()) first = SendFailure{n < 0 ? errno : 0, "sendmmsg"};
      failed_[done++] = true;
      continue;
    }
    for (std::size_t i = done; i < done + static_cast<std::size_t>(n); ++i) {
      if (headers_[i].msg_len != slots_[i].bytes) {
        failed_[i] = true;
        if (!first.failed()) first = SendFailure{0, "sendmmsg sent part of a datagram"};
      }
    }
    done += static_cast<std::size_t>(n);
  }
  count_ = 0;
  return first;
}

}  // namespace cosmic::lcm_detail

#include "can_adapter_impl.hpp"
#include "cosmic/receive_buffer_size.hpp"

namespace cosmic::can_detail {

// ------------------------------------------------------------------------------ socket and link

void CanAdapter::close_socket() {
  if (census_sock_ >= 0) {
    ::close(census_sock_);
    census_sock_ = -1;
  }
  PiLock lock(io_mutex_);
  if (sock_ < 0) return;
  tx_socket_.reset();  // closes the descriptor, or the last sender still writing to it does
  sock_ = -1;
  bound_ifindex_ = 0;
  overflow_closed_ += overflow_socket_.exchange(0);
  wait_pollout_ = false;
}

bool CanAdapter::open_socket(int ifindex) {
  const std::string& ifname = segment_.can.interface;
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (s < 0) {
    set_link(Link::down, "SocketCAN is not available: " + errno_text(errno));
    return false;
  }
  auto fail = [&](const std::string& what) {
    const int err = errno;
    ::close(s);
    set_link(Link::down, what + " on " + ifname + ": " + errno_text(err));
    return false;
  };
  const int on = 1;
  if (segment_.can.fd && ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) != 0) {
    return fail("CAN_RAW_FD_FRAMES");
  }
  const can_err_mask_t err_mask = kErrorMask;
  if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0) {
    return fail("CAN_RAW_ERR_FILTER");
  }
  if (::setsockopt(s, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) return fail("SO_RXQ_OVFL");
  if (::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) return fail("SO_TIMESTAMPNS");
  size_receive_buffer(s);

  // Filters go on before bind: no frame of an unbound etag is ever queued to this socket. A
  // configure() racing with this is caught below by the generation check.
  std::uint64_t generation = 0;
  for (;;) {
    std::vector<can_filter> filters;
    {
      PiLock lock(io_mutex_);
      generation = generation_.load();
      filters = table_->filters;
    }
    if (filters.empty()) filters = protocol_filters(famouso_protocol_);
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0) {
      return fail("CAN_RAW_FILTER");
    }
    PiLock lock(io_mutex_);
    if (generation == generation_.load()) break;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifindex;
  if (::bind(s, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return fail("bind");
  PiLock lock(io_mutex_);
  if (generation != generation_.load() &&
      ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, table_->filters.data(),
                   static_cast<socklen_t>(table_->filters.size() * sizeof(can_filter))) != 0) {
    const int err = errno;
    ::close(s);
    log_.log(LogLevel::error, prefix_ + "CAN_RAW_FILTER: " + errno_text(err));
    return false;
  }
  if (sock_ >= 0) overflow_closed_ += overflow_socket_.exchange(0);
  try {
    tx_socket_ = std::make_shared<const TxSocket>(s);
  } catch (const std::bad_alloc&) {
    ::close(s);
    tx_socket_.reset();
    sock_ = -1;
    return false;
  }
  sock_ = s;
  bound_ifindex_ = ifindex;
  wait_pollout_ = false;
  open_census_socket(ifindex);
  return true;
}

// SO_RCVBUFFORCE where the process may (CAP_NET_ADMIN), else SO_RCVBUF, which the kernel caps at
// net.core.rmem_max. Short of receive_buffer_frames(), one warning says what the socket holds
// and what would give it the rest; it runs on regardless.
void CanAdapter::size_receive_buffer(int s) {
  const std::size_t wanted = receive_buffer_frames(segment_.can);
  const int request = receive_buffer_request(wanted);
  const std::size_t held = frames_held(cosmic::size_receive_buffer(s, request).reported);
  if (held >= wanted || receive_buffer_warned_) return;
  receive_buffer_warned_ = true;
  log_.log(LogLevel::warning,
           prefix_ + "the receive buffer of " + segment_.can.interface + " holds " + std::to_string(held) +
               " frames, not the " + std::to_string(wanted) + " the bus carries in " +
               std::to_string(kReceiveHold.count() / 1'000'000) +
               " ms: frames of a longer burst are lost when the receive thread falls behind (counted as "
               "overflow drops). Set net.core.rmem_max to at least " +
               std::to_string(request) + " or give cosmicd CAP_NET_ADMIN (SO_RCVBUFFORCE); see docs/operations.md");
}

// Unfiltered and with a small receive buffer: when the receive thread falls behind, the kernel
// drops census frames, never the channels' (they have their own socket, read first).
void CanAdapter::open_census_socket(int ifindex) {
  if (census_sock_ >= 0) ::close(census_sock_);
  census_sock_ = -1;
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  const int on = 1;
  const int buffer = 64 * 1024;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifindex;
  const bool ok = s >= 0 &&
                  (!segment_.can.fd || ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) == 0) &&
                  ::setsockopt(s, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer) == 0 &&
                  ::bind(s, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
  if (ok) {
    census_sock_ = s;
    return;
  }
  const int err = errno;
  if (s >= 0) ::close(s);
  if (!census_error_logged_) {
    census_error_logged_ = true;
    log_.log(LogLevel::warning, prefix_ + "no census socket (unexplained frames are not counted): " + errno_text(err));
  }
}

void CanAdapter::check_link() {
  const std::string& ifname = segment_.can.interface;
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, ifname.data(), ifname.size());
  if (::ioctl(ctl_fd_, SIOCGIFINDEX, &ifr) != 0) {
    const int err = errno;
    close_socket();
    set_link(Link::down, err == ENODEV ? "no such interface " + ifname
                                       : "cannot look up interface " + ifname + ": " + errno_text(err));
    return;
  }
  const int ifindex = ifr.ifr_ifindex;
  if (::ioctl(ctl_fd_, SIOCGIFHWADDR, &ifr) == 0 && ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
    close_socket();
    set_link(Link::down, "interface " + ifname + " is not a CAN interface");
    return;
  }
  if (::ioctl(ctl_fd_, SIOCGIFFLAGS, &ifr) != 0) {
    set_link(Link::down, "cannot read the flags of " + ifname + ": " + errno_text(errno));
    return;
  }
  const short flags = ifr.ifr_flags;
  bool have_socket = false;
  {
    PiLock lock(io_mutex_);
    have_socket = sock_ >= 0 && bound_ifindex_ == ifindex;
  }
  if (!have_socket && !open_socket(ifindex)) return;  // open_socket set the health
  if (!(flags & IFF_UP)) {
    set_link(Link::down, "interface " + ifname + " is down");
    return;
  }
  if (!(flags & IFF_RUNNING)) {
    set_link(Link::down, "interface " + ifname + " has no carrier (bus-off or controller stopped)");
    return;
  }
  if (segment_.can.fd) {
    if (::ioctl(ctl_fd_, SIOCGIFMTU, &ifr) == 0 && ifr.ifr_mtu != static_cast<int>(CANFD_MTU)) {
      set_link(Link::down, "interface " + ifname + " is not in CAN FD mode (mtu " + std::to_string(ifr.ifr_mtu) +
                               ", needs " + std::to_string(CANFD_MTU) + ")");
      return;
    }
  }
  set_link(Link::up, "");
}

// ------------------------------------------------------------------------------ receive thread

void CanAdapter::run() {
  next_link_check_ = steady_now() + (link_up_ ? kLinkCheckWhileUp : kLinkCheckWhileDown);
  while (!receiver_.stopping()) {
    Nanos now = steady_now();
    if (now >= next_link_check_) {
      check_link();
      now = steady_now();
      next_link_check_ = now + (link_up_ ? kLinkCheckWhileUp : kLinkCheckWhileDown);
    }
    refresh_rx_table();
    const std::function<void(std::uint32_t)> expired = [this](std::uint32_t source) {
      reassembly_losses(kNoChannel, source, false);
    };
    cosmic_frames_.expire(now, expired);
    famouso_frames_.expire(now, expired);
    handle_protocol_timeouts(now);
    serve_deferred_requests(now);

    pollfd fds[3] = {{receiver_.wake_fd(), POLLIN, 0}, {-1, 0, 0}, {census_sock_, POLLIN, 0}};
    Nanos deadline = next_link_check_;
    for (const auto d : {cosmic_frames_.next_deadline(), famouso_frames_.next_deadline()}) {
      if (d) deadline = std::min(deadline, *d + Nanos(1));
    }
    if (const auto d = ccp_ ? ccp_->deadline() : std::nullopt) deadline = std::min(deadline, *d);
    {
      PiLock lock(io_mutex_);
      if (const auto d = answers_.deadline(); d && backlog_.empty()) deadline = std::min(deadline, *d);
      if (!deferred_requests_.empty()) deadline = std::min(deadline, now + kDeferredRequestRetry);
      if (sock_ >= 0) {
        fds[1].fd = sock_;
        fds[1].events = POLLIN;
        if (!backlog_.empty() && wait_pollout_) fds[1].events |= POLLOUT;
      }
      if (!backlog_.empty() && retry_at_) deadline = std::min(deadline, *retry_at_);
    }
    const auto wait_ms = std::chrono::ceil<milliseconds>(std::max(Nanos(0), deadline - now)).count();
    const int ready = ::poll(fds, 3, static_cast<int>(std::min<std::int64_t>(wait_ms, 1000)));
    if (ready < 0 && errno != EINTR) {
      log_.log(LogLevel::error, prefix_ + "poll: " + errno_text(errno));
      std::this_thread::sleep_for(milliseconds(10));
      continue;
    }
    if (receiver_.stopping()) break;
    if (fds[0].revents & POLLIN) receiver_.clear_wakes();
    if (fds[1].fd >= 0 && (fds[1].revents & (POLLIN | POLLERR | POLLHUP))) read_frames();
    drain_backlog();
    drain_answers();
    // After the channels' frames and the sends: the census never delays them.
    if (fds[2].fd >= 0 && fds[2].fd == census_sock_ && (fds[2].revents & POLLIN)) read_census();
  }
}

// Reads what the socket holds in batches of kReadBatch frames per system call (recvmmsg), each
// with its kernel arrival time (SO_TIMESTAMPNS) and the socket's drop count (SO_RXQ_OVFL).
void CanAdapter::read_frames() {
  const int s = receive_socket();
  constexpr std::size_t kControlBytes = CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t));
  struct Slot {
    canfd_frame frame;
    iovec iov;
    alignas(cmsghdr) char control[kControlBytes];
  };
  std::array<Slot, kReadBatch> slots;
  std::array<mmsghdr, kReadBatch> messages;
  for (int round = 0; round < kFramesPerWakeup / static_cast<int>(kReadBatch) && s >= 0 && receive_socket() == s;
       ++round) {
    for (std::size_t i = 0; i < kReadBatch; ++i) {
      slots[i].iov = iovec{&slots[i].frame, sizeof(canfd_frame)};
      messages[i] = mmsghdr{};
      messages[i].msg_hdr.msg_iov = &slots[i].iov;
      messages[i].msg_hdr.msg_iovlen = 1;
      messages[i].msg_hdr.msg_control = slots[i].control;
      messages[i].msg_hdr.msg_controllen = kControlBytes;
    }
    const int n = ::recvmmsg(s, messages.data(), kReadBatch, MSG_DONTWAIT, nullptr);
    if (n < 0) {
      handle_read_error(errno);
      return;
    }
    for (int i = 0; i < n; ++i) handle_datagram(slots[i].frame, messages[i].msg_hdr, messages[i].msg_len);
    if (static_cast<std::size_t>(n) < kReadBatch) return;  // drained
  }
}

void CanAdapter::read_census() {
  std::array<canfd_frame, kReadBatch> frames;
  std::array<iovec, kReadBatch> iovs;
  std::array<mmsghdr, kReadBatch> messages;
  for (int round = 0; round < kFramesPerWakeup / static_cast<int>(kReadBatch) && census_sock_ >= 0; ++round) {
    for (std::size_t i = 0; i < kReadBatch; ++i) {
      iovs[i] = iovec{&frames[i], sizeof(canfd_frame)};
      messages[i] = mmsghdr{};
      messages[i].msg_hdr.msg_iov = &iovs[i];
      messages[i].msg_hdr.msg_iovlen = 1;
    }
    const int n = ::recvmmsg(census_sock_, messages.data(), kReadBatch, MSG_DONTWAIT, nullptr);
    if (n <= 0) return;  // drained, or the interface went: check_link() reopens both sockets
    refresh_rx_table();
    const Nanos now = steady_now();
    for (int i = 0; i < n; ++i) {
      const canid_t id = frames[static_cast<std::size_t>(i)].can_id;
      if (!(id & CAN_ERR_FLAG) && !explains(*rx_table_, id)) census_.count(id, now);
    }
    if (static_cast<std::size_t>(n) < kReadBatch) return;
  }
}

// A bound channel's frame (either layout, either role), a binding protocol's or a declared
// background frame.
bool CanAdapter::explains(const Table& table, canid_t can_id) const {
  if (table.native.explains(can_id)) return true;
  if (!(can_id & CAN_EFF_FLAG)) return false;
  const auto etag = static_cast<std::uint16_t>(can_id & kEtagMask);
  return etag <= kHighestReservedEtag || table.rx.count(etag) != 0 || table.tx_etags.count(etag) != 0;
}

void CanAdapter::handle_read_error(int err) {
  if (err == EAGAIN || err == EWOULDBLOCK || err == EINTR) return;
  if (err == ENETDOWN) {
    set_link(Link::down, "interface " + segment_.can.interface + " is down");
    next_link_check_ = steady_now() + kLinkCheckWhileDown;
    return;
  }
  if (err == ENODEV) {
    close_socket();
    set_link(Link::down, "no such interface " + segment_.can.interface);
    next_link_check_ = steady_now() + kLinkCheckWhileDown;
    return;
  }
  counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
  log_.log(LogLevel::warning, prefix_ + "recvmmsg: " + errno_text(err));
}

void CanAdapter::handle_datagram(canfd_frame& frame, msghdr& msg, std::size_t bytes) {
  std::int64_t arrival_ns = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t drops = 0;
      std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      overflow_socket_ = drops;
    } else if (c->cmsg_type == SO_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      arrival_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
    }
  }
  const Nanos arrival = steady_arrival_now(arrival_ns);
  if (bytes != CAN_MTU && bytes != CANFD_MTU) {
    problem(kNoChannel, InboundProblem::decode_error);
    return;
  }
  const bool fd_frame = bytes == CANFD_MTU;
  if (!fd_frame) frame.flags = 0;  // the byte is padding in struct can_frame
  if (tap_) {
    const WireUnit unit{WireDirection::received,
                        arrival,
                        arrival_ns != 0 ? arrival_ns : realtime_now_ns(),
                        {reinterpret_cast<const std::uint8_t*>(&frame), bytes}};
    tap_->on_wire(unit);
  }
  handle_frame(frame, fd_frame, arrival);
}

}  // namespace cosmic::can_detail

#include "can_adapter_impl.hpp"

namespace cosmic::can_detail {

// ------------------------------------------------------------------------------ send side

void CanAdapter::drop_backlog(const char* why) {
  if (backlog_.empty()) return;
  send_errors_ += backlog_.size();
  log_.log(LogLevel::warning, "segment " + segment_.name + ": dropped " + std::to_string(backlog_.size()) +
                                  " queued frames (" + why + ")");
  backlog_.clear();
  backlog_size_ = 0;
  wait_pollout_ = false;
  retry_at_.reset();
}

CanAdapter::WriteResult CanAdapter::submit(const canfd_frame& frame, bool fd) {
  if (sock_ < 0) {
    ++send_errors_;
    return WriteResult::failed;
  }
  if (!backlog_.empty()) {
    if (!backlog_.push(frame, fd)) {
      ++send_errors_;
      return WriteResult::full;
    }
    backlog_size_ = backlog_.size();
    return WriteResult::queued;
  }
  const std::size_t mtu = fd ? CANFD_MTU : CAN_MTU;
  const ssize_t n = ::write(sock_, &frame, mtu);
  if (n == static_cast<ssize_t>(mtu)) {
    ++sent_;
    return WriteResult::written;
  }
  const int err = n < 0 ? errno : EIO;
  if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
    backlog_.push(frame, fd);  // the backlog is empty here: there is room
    backlog_size_ = backlog_.size();
    wait_pollout_ = err != ENOBUFS;
    if (err == ENOBUFS) retry_at_ = steady_now() + kEnobufsRetry;
    wake();
    return WriteResult::queued;
  }
  ++send_errors_;
  if (!send_error_logged_) {
    send_error_logged_ = true;
    log_.log(LogLevel::warning, "segment " + segment_.name + ": write to " + segment_.can.interface + ": " +
                                    errno_text(err) + " (further errors counted, not logged)");
  }
  return WriteResult::failed;
}

void CanAdapter::drain_backlog() {
  LockGuard lock(io_mutex_);
  if (backlog_.empty() || sock_ < 0) return;
  if (retry_at_ && steady_now() < *retry_at_) return;
  retry_at_.reset();
  wait_pollout_ = false;
  while (!backlog_.empty()) {
    const auto& entry = backlog_.top();
    const std::size_t mtu = entry.fd ? CANFD_MTU : CAN_MTU;
    const ssize_t n = ::write(sock_, &entry.frame, mtu);
    if (n == static_cast<ssize_t>(mtu)) {
      ++sent_;
      backlog_.pop();
      continue;
    }
    const int err = n < 0 ? errno : EIO;
    if (err == EAGAIN || err == EWOULDBLOCK) {
      wait_pollout_ = true;
      break;
    }
    if (err == ENOBUFS) {
      retry_at_ = steady_now() + kEnobufsRetry;
      break;
    }
    if (err == ENETDOWN) {
      drop_backlog("interface down");
      break;
    }
    ++send_errors_;
    backlog_.pop();
  }
  backlog_size_ = backlog_.size();
}

SendStatus CanAdapter::send(const OutboundEvent& event) {
  try {
    UniqueLock lock(io_mutex_);
    const std::shared_ptr<const Table> table = table_;  // kept alive while the lock is given up
    const auto it = table->tx.find(event.channel);
    if (it == table->tx.end() || !started_ || !link_up_ || sock_ < 0 || event.payload.size() > it->second.payload) {
      ++send_errors_;
      return SendStatus::failed;
    }
    const TxChannel& channel = it->second;
    const bool fd = segment_.can.fd;
    if (channel.native) return send_frame(can_native::encode(*channel.native, event.payload, fd, brs_));
    canfd_frame frame{};
    frame.can_id = channel.can_id | CAN_EFF_FLAG;
    frame.flags = fd && brs_ ? CANFD_BRS : 0;
    auto finish = [&](std::size_t len) {
      const std::size_t wire = fd ? fd_padded_length(static_cast<std::uint32_t>(len)) : len;
      std::memset(frame.data + len, 0, sizeof frame.data - len);
      frame.len = static_cast<std::uint8_t>(wire);
    };
    if (famouso_ && event.payload.size() > famouso::kAfpMtu) return send_afp(channel, event.payload, lock);
    if (!channel.fragmented || famouso_) {  // FAMOUSO: events of up to 8 bytes are plain frames
      std::memcpy(frame.data, event.payload.data(), event.payload.size());
      finish(event.payload.size());
      return send_frame(frame);
    }
    const std::uint32_t count = fragment_count(event.payload.size(), capacity_);
    if (!backlog_.empty() && !backlog_.room_for(count)) {
      ++send_errors_;
      return SendStatus::queue_full;
    }
    std::uint8_t& sequence = tx_sequence_[channel.etag];
    Fragmenter fragments(event.payload, capacity_, sequence);
    sequence = static_cast<std::uint8_t>((sequence + 1) % kFragmentSequenceModulo);
    // The lock is given up between fragments, so a higher class sending on this bus from its own
    // thread waits for at most one frame write, not for a whole fragmented event.
    while (!fragments.done()) {
      const std::size_t len = fragments.next(std::span<std::uint8_t>(frame.data, capacity_));
      finish(len);
      const WriteResult r = submit(frame, fd);
      if (r == WriteResult::failed || r == WriteResult::full) return SendStatus::failed;
      if (!fragments.done()) {
        lock.unlock();
        lock.lock();
        if (sock_ < 0) return SendStatus::failed;
      }
    }
    return SendStatus::sent;
  } catch (...) {
    ++send_errors_;
    return SendStatus::failed;
  }
}

SendStatus CanAdapter::send_frame(const canfd_frame& frame) {
  switch (submit(frame, segment_.can.fd)) {
    case WriteResult::written:
    case WriteResult::queued:
      return SendStatus::sent;
    case WriteResult::full:
      return SendStatus::queue_full;
    case WriteResult::failed:
      return SendStatus::failed;
  }
  return SendStatus::failed;
}

// FAMOUSO: an event of more than 8 bytes as AFP fragments with the identifier's fragment flag.
SendStatus CanAdapter::send_afp(const TxChannel& channel, std::span<const std::uint8_t> payload,
                                UniqueLock& lock) {
  if (!backlog_.empty() && !backlog_.room_for(famouso::afp_fragment_count(payload.size()))) {
    ++send_errors_;
    return SendStatus::queue_full;
  }
  famouso::AfpFragmenter fragments(payload);
  canfd_frame frame{};
  frame.can_id = channel.afp_id | CAN_EFF_FLAG;
  while (!fragments.done()) {
    frame.len = static_cast<std::uint8_t>(fragments.next(std::span<std::uint8_t>(frame.data, famouso::kAfpMtu)));
    const WriteResult r = submit(frame, false);
    if (r == WriteResult::failed || r == WriteResult::full) return SendStatus::failed;
    if (!fragments.done()) {  // as in send(): a higher class waits for at most one frame
      lock.unlock();
      lock.lock();
      if (sock_ < 0) return SendStatus::failed;
    }
  }
  return SendStatus::sent;
}

}  // namespace cosmic::can_detail

#include "can_adapter_impl.hpp"

namespace cosmic::can_detail {

// ------------------------------------------------------------------------------ send side
//
// The lanes of every class and the receive thread (backlog, binding answers) write to the one
// CAN_RAW socket. None of them holds io_mutex_ across a system call: under it they only decide
// (write now or queue behind the backlog) and take a reference to the socket. An NRT sender held
// up in the kernel or preempted mid-write therefore never delays an HRT sender, which writes in
// parallel; the kernel keeps each frame whole.

namespace {

bool kernel_full(int err) { return err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS; }

// Writes `frames` in one system call where there are several; returns how many the kernel took
// (the error of the first refused one in `err`).
std::size_t write_frames(int fd, std::span<const canfd_frame> frames, bool fd_frames, int& err) {
  const std::size_t mtu = fd_frames ? CANFD_MTU : CAN_MTU;
  err = 0;
  if (frames.size() == 1) {
    const ssize_t n = ::write(fd, frames.data(), mtu);
    if (n == static_cast<ssize_t>(mtu)) return 1;
    err = n < 0 ? errno : EIO;
    return 0;
  }
  std::array<iovec, kWriteBatch> iovs;
  std::array<mmsghdr, kWriteBatch> messages;
  const std::size_t count = std::min(frames.size(), kWriteBatch);
  for (std::size_t i = 0; i < count; ++i) {
    iovs[i] = iovec{const_cast<canfd_frame*>(&frames[i]), mtu};
    messages[i] = mmsghdr{};
    messages[i].msg_hdr.msg_iov = &iovs[i];
    messages[i].msg_hdr.msg_iovlen = 1;
  }
  const int n = ::sendmmsg(fd, messages.data(), static_cast<unsigned>(count), MSG_DONTWAIT);
  if (n < 0) {
    err = errno;
    return 0;
  }
  // A short count means the next frame was refused; its error shows on the next write.
  if (static_cast<std::size_t>(n) < count) err = EAGAIN;
  return static_cast<std::size_t>(n);
}

}  // namespace

void CanAdapter::tap_sent(std::span<const canfd_frame> frames, bool fd) const noexcept {
  if (!tap_ || frames.empty()) return;
  const Nanos now = steady_now();
  const std::int64_t utc = realtime_now_ns();
  for (const canfd_frame& frame : frames) {
    canfd_frame seen = frame;
    // As every reader of the bus gets it: the kernel marks each CAN FD frame it carries with
    // CANFD_FDF (linux/can.h), so the tap's received and sent FD frames look alike.
    if (fd) seen.flags |= CANFD_FDF;
    tap_->on_wire(WireUnit{
        WireDirection::sent, now, utc, {reinterpret_cast<const std::uint8_t*>(&seen), fd ? CANFD_MTU : CAN_MTU}});
  }
}

std::string CanAdapter::drop_backlog(const char* why) {
  if (backlog_.empty()) return {};
  counters_.send_errors.fetch_add(backlog_.size(), std::memory_order_relaxed);
  std::string line = prefix_ + "dropped " + std::to_string(backlog_.size()) + " queued frames (" + why + ")";
  backlog_.clear();
  backlog_size_ = 0;
  wait_pollout_ = false;
  retry_at_.reset();
  return line;
}

void CanAdapter::log_unlocked(const std::string& line) {
  if (!line.empty()) log_.log(LogLevel::warning, line);
}

bool CanAdapter::behind_backlog(canid_t can_id) const {
  const std::uint32_t mine = frame_arbitration_key(can_id);
  if (!backlog_.empty() && frame_arbitration_key(backlog_.top().frame.can_id) <= mine) return true;
  return draining_key_ && *draining_key_ <= mine;
}

CanAdapter::WriteResult CanAdapter::queue_frames(std::span<const canfd_frame> frames, bool fd) {
  if (!backlog_.room_for(frames.size())) {
    counters_.send_errors.fetch_add(frames.size(), std::memory_order_relaxed);
    return WriteResult::full;
  }
  for (const canfd_frame& frame : frames) backlog_.push(frame, fd);
  backlog_size_ = backlog_.size();
  return WriteResult::queued;
}

void CanAdapter::note_refusal(int err) {
  wait_pollout_ = err != ENOBUFS;
  if (err == ENOBUFS) retry_at_ = steady_now() + kEnobufsRetry;
}

std::string CanAdapter::count_send_error(int err) {
  counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
  if (send_error_logged_) return {};
  send_error_logged_ = true;
  return prefix_ + "write to " + segment_.can.interface + ": " + errno_text(err) +
         " (further errors counted, not logged)";
}

SendStatus CanAdapter::to_send_status(WriteResult result) {
  switch (result) {
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

CanAdapter::WriteResult CanAdapter::submit(std::span<const canfd_frame> frames, bool fd) {
  TxSocketRef socket;
  std::optional<WriteResult> queued;
  {
    PiLock lock(io_mutex_);
    if (!tx_socket_) {
      counters_.send_errors.fetch_add(frames.size(), std::memory_order_relaxed);
      return WriteResult::failed;
    }
    const bool one_identifier = std::all_of(frames.begin(), frames.end(),
                                            [&](const canfd_frame& f) { return f.can_id == frames.front().can_id; });
    const bool backlog_busy = !backlog_.empty() || draining_key_.has_value();
    if (behind_backlog(frames.front().can_id) || (backlog_busy && !one_identifier)) {
      queued = queue_frames(frames, fd);
    } else {
      socket = tx_socket_;
    }
  }
  if (queued) {
    wake();  // the receive thread may be past its last look at the backlog
    return *queued;
  }
  std::size_t written = 0;
  int err = 0;
  while (written < frames.size()) {
    const std::size_t n = write_frames(socket->fd(), frames.subspan(written), fd, err);
    tap_sent(frames.subspan(written, n), fd);
    written += n;
    counters_.sent.fetch_add(n, std::memory_order_relaxed);
    if (err != 0) break;
  }
  if (written == frames.size()) return WriteResult::written;
  WriteResult result = WriteResult::failed;
  std::string log_line;  // logged after the lock is given up: the log may block
  {
    PiLock lock(io_mutex_);
    if (!kernel_full(err) || !tx_socket_) {
      // Refused for good, or the socket went away mid-event: the rest of the event is worthless.
      log_line = count_send_error(err);
      counters_.send_errors.fetch_add(frames.size() - written - 1, std::memory_order_relaxed);
    } else {
      // The kernel's queue is full: the rest waits in the backlog (in order: one identifier).
      result = queue_frames(frames.subspan(written), fd);
      if (result == WriteResult::queued) note_refusal(err);
    }
  }
  log_unlocked(log_line);
  if (result == WriteResult::queued) wake();
  return result;
}

// Receive thread: the backlog in arbitration order, a batch of frames per system call. The
// frames being written count as queued (draining_key_) so no sender overtakes them meanwhile.
void CanAdapter::drain_backlog() {
  std::array<FrameBacklog::Entry, kWriteBatch> taken;
  std::array<canfd_frame, kWriteBatch> frames;
  for (int round = 0; round < kFramesPerWakeup / static_cast<int>(kWriteBatch); ++round) {
    TxSocketRef socket;
    std::size_t count = 0;
    bool fd = false;
    {
      PiLock lock(io_mutex_);
      if (backlog_.empty() || !tx_socket_) return;
      if (retry_at_ && steady_now() < *retry_at_) return;
      retry_at_.reset();
      wait_pollout_ = false;
      fd = backlog_.top().fd;
      // One batch writes one MTU: classic and FD frames are not mixed in it.
      while (count < kWriteBatch && !backlog_.empty() && backlog_.top().fd == fd) taken[count++] = backlog_.take();
      draining_key_ = frame_arbitration_key(taken[0].frame.can_id);
      socket = tx_socket_;
    }
    for (std::size_t i = 0; i < count; ++i) frames[i] = taken[i].frame;
    int err = 0;
    const std::size_t written = write_frames(socket->fd(), std::span(frames.data(), count), fd, err);
    tap_sent(std::span(frames.data(), written), fd);
    counters_.sent.fetch_add(written, std::memory_order_relaxed);
    std::string log_line;
    {
      PiLock lock(io_mutex_);
      draining_key_.reset();
      std::size_t next = written;
      if (err != 0 && !kernel_full(err) && err != ENETDOWN && next < count) {
        counters_.send_errors.fetch_add(1, std::memory_order_relaxed);  // this frame cannot be sent; the others may
        ++next;
      }
      backlog_.settle(next);
      for (std::size_t i = next; i < count; ++i) backlog_.restore(taken[i]);
      backlog_size_ = backlog_.size();
      if (err == ENETDOWN) {
        log_line = drop_backlog("interface down");
      } else if (kernel_full(err)) {
        note_refusal(err);
        return;
      }
    }
    if (err == ENETDOWN) {
      log_unlocked(log_line);
      return;
    }
  }
  // A full round's worth written and frames still queued: nothing else may wake the receive
  // thread (no POLLOUT wait, no retry time), so it comes back at once.
  bool more = false;
  {
    PiLock lock(io_mutex_);
    more = !backlog_.empty();
  }
  if (more) wake();
}

SendStatus CanAdapter::send(const OutboundEvent& event) {
  try {
    std::shared_ptr<const Table> table;  // keeps `binding` alive without the lock
    std::uint8_t sequence = 0;
    std::size_t frames = 1;
    const CanTxBinding* found = nullptr;
    {
      PiLock lock(io_mutex_);
      table = table_;
      const auto it = table->tx.find(event.channel);
      if (it == table->tx.end() || !started_ || !link_up_ || !tx_socket_ || event.payload.size() > it->second.payload) {
        counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
        return SendStatus::failed;
      }
      found = &it->second;
      frames = found->format->frame_count(*found, event.payload.size());
      if (frames > 1 && !backlog_.empty() && !backlog_.room_for(frames)) {
        counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
        return SendStatus::queue_full;
      }
      if (found->format->numbered(*found)) {  // every event of the channel is numbered
        std::uint8_t& next = tx_sequence_[found->etag];
        sequence = next;
        next = static_cast<std::uint8_t>((next + 1) % kFragmentSequenceModulo);
      }
    }
    const CanTxBinding& binding = *found;
    const bool fd = segment_.can.fd;
    std::array<std::uint8_t, CANFD_MAX_DLEN> secured;
    const std::span<const std::uint8_t> payload = secure(binding, event.payload, secured);
    if (binding.secoc && payload.empty()) return SendStatus::failed;
    // The first refused batch ends the event: no frame the kernel did not take counts as sent.
    WriteResult refused = WriteResult::written;
    // Batch by batch to submit(): one system call each.
    CanFrameBatchTo sink([&](std::span<const canfd_frame> frames) {
      const WriteResult r = submit(frames, fd);
      if (r == WriteResult::failed || r == WriteResult::full) refused = r;
      return refused == WriteResult::written;
    });
    if (binding.format->encode(binding, payload, sequence, sink)) return SendStatus::sent;
    // One frame refused: as the kernel or the backlog answered; part of a fragmented event: lost.
    return frames == 1 ? to_send_status(refused) : SendStatus::failed;
  } catch (...) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return SendStatus::failed;
  }
}

const CanTxBinding* CanAdapter::single_frame_binding(const Table& table, const OutboundEvent& event) {
  const auto it = table.tx.find(event.channel);
  if (it == table.tx.end() || event.payload.size() > it->second.payload) return nullptr;
  const CanTxBinding& binding = it->second;
  return binding.format->frame_count(binding, event.payload.size()) == 1 ? &binding : nullptr;
}

void CanAdapter::send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) {
  const bool fd = segment_.can.fd;
  std::array<canfd_frame, kWriteBatch> frames;
  std::size_t i = 0;
  while (i < events.size() && i < results.size()) {
    std::shared_ptr<const Table> table;  // keeps the bindings alive without the lock
    const std::size_t first = i;
    std::size_t count = 0;
    {
      PiLock lock(io_mutex_);
      if (started_ && link_up_ && tx_socket_) {
        table = table_;
        for (; i < events.size() && i < results.size() && count < kWriteBatch; ++i) {
          const CanTxBinding* binding = single_frame_binding(*table, events[i]);
          if (binding == nullptr || binding->secoc) break;  // send() protects and counts SecOC frames
          frames[count++] = binding->format->single_frame(*binding, events[i].payload);
        }
      }
    }
    if (count == 0) {  // not one frame, or not sendable now: send() sends or counts it
      results[i] = send(events[i]);
      ++i;
      continue;
    }
    const SendStatus status = to_send_status(submit(std::span(frames.data(), count), fd));
    std::fill(results.begin() + static_cast<std::ptrdiff_t>(first), results.begin() + static_cast<std::ptrdiff_t>(i),
              status);
  }
}

}  // namespace cosmic::can_detail

#include "can_adapter_impl.hpp"

namespace cosmic::can_detail {

void CanAdapter::problem(ChannelId channel, InboundProblem what) {
  counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
  if (sink_) sink_->on_problem(channel, what);
}

void CanAdapter::handle_frame(const canfd_frame& frame, bool fd_frame, Nanos now) {
  if (frame.can_id & CAN_ERR_FLAG) {
    handle_error_frame(frame);
    return;
  }
  counters_.received.fetch_add(1, std::memory_order_relaxed);
  const std::size_t len = std::min<std::size_t>(frame.len, fd_frame ? CANFD_MAX_DLEN : CAN_MAX_DLEN);
  refresh_rx_table();
  const Table& table = *rx_table_;
  // Native identifiers first: an extended one may have any bits in the etag field.
  if (const can_native::RxChannel* native = table.native.find(frame.can_id)) {
    receive(CanRxBinding{native->id, &native_frames_, native->subject, native->payload, false, native->secoc},
            frame.can_id, std::span<const std::uint8_t>(frame.data, len), fd_frame, now);
    return;
  }
  if (table.native.is_background(frame.can_id)) return;  // another device's declared frame
  if (!(frame.can_id & CAN_EFF_FLAG)) {                  // an 11-bit frame: not ours (only without kernel filters)
    problem(kNoChannel, InboundProblem::unknown_channel);
    return;
  }
  const CanIdentifier id = decode_can_id(frame.can_id & CAN_EFF_MASK);
  if (id.etag == kEtagGetEtag) {
    if (frame.can_id & CAN_RTR_FLAG) {
      problem(kNoChannel, InboundProblem::decode_error);
    } else {
      handle_get_etag(frame, len, now);
    }
    return;
  }
  if (famouso_protocol_ && (id.etag == kEtagCcpRsi || id.etag == kEtagFamousoSubscribe)) {
    handle_famouso_protocol(id, frame, len, now);
    return;
  }
  const auto it = table.rx.find(id.etag);
  if (it == table.rx.end()) {
    problem(kNoChannel, InboundProblem::unknown_channel);
    return;
  }
  if (frame.can_id & CAN_RTR_FLAG) {
    problem(it->second.id, InboundProblem::decode_error);
    return;
  }
  receive(it->second, frame.can_id, std::span<const std::uint8_t>(frame.data, len), fd_frame, now);
}

void CanAdapter::receive(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data, bool fd_frame,
                         Nanos now) {
  const std::optional<std::span<const std::uint8_t>> authentic = authenticate(binding, can_id, data, fd_frame);
  if (!authentic) return;
  const CanDecoded decoded = binding.format->decode(binding, can_id, *authentic, fd_frame, now);
  reassembly_losses(binding.id, decoded.displaced, decoded.lost);
  if (decoded.event) deliver(binding, *decoded.event, now);
}

// Every event lost in reassembly is counted on its channel; `displaced` is a source (TxNode and
// etag) whose partial event was given up: for a newcomer, or idle too long.
void CanAdapter::reassembly_losses(ChannelId channel, std::optional<std::uint32_t> displaced, bool lost) {
  if (displaced) {
    const auto other = rx_table_->rx.find(static_cast<std::uint16_t>(*displaced & 0x3FFF));
    problem(other == rx_table_->rx.end() ? kNoChannel : other->second.id, InboundProblem::decode_error);
  }
  if (lost) problem(channel, InboundProblem::decode_error);
}

// FAMOUSO segments: CCP requests (node ids) and SUBSCRIBE announcements.
void CanAdapter::handle_famouso_protocol(const CanIdentifier& id, const canfd_frame& frame, std::size_t len,
                                         Nanos now) {
  const Table& table = *rx_table_;
  if (id.etag == kEtagCcpRsi) {
    if (table.tx_node) ccp_->reserve(*table.tx_node);
    const auto answer = ccp_->on_request(frame.can_id & CAN_EFF_MASK, now);
    if (answer) {
      PiLock lock(io_mutex_);
      queue_answer(answer->can_id, answer->data);
    } else if (ccp_->exhausted()) {
      problem(kNoChannel, InboundProblem::decode_error);
      log_.log(LogLevel::warning, prefix_ + "CCP: every TxNode is taken, a node stays unconfigured");
    }
    return;
  }
  // A FAMOUSO node announces each subject it subscribes on the SUBSCRIBE subject's etag. The
  // gateway forwards what is bound, so the announcement is only worth a line in the log.
  if (len != can_binding::kFrameBytes) {
    problem(kNoChannel, InboundProblem::decode_error);
    return;
  }
  std::uint64_t subject = 0;
  for (std::size_t i = 0; i < len; ++i) subject = (subject << 8) | frame.data[i];
  const std::pair<std::uint8_t, std::uint64_t> key{id.tx_node, subject};
  if (announced_.size() >= kMaxAnnouncedSubscriptions ||
      std::find(announced_.begin(), announced_.end(), key) != announced_.end()) {
    return;
  }
  announced_.push_back(key);
  const bool bound = table.etag_of.count(subject) != 0;
  char text[64];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(subject));
  log_.log(LogLevel::notice, prefix_ + "FAMOUSO node " + std::to_string(id.tx_node) + " subscribes subject " + text +
                                 (bound ? "" : " (no channel bound for it)"));
}

void CanAdapter::deliver(const CanRxBinding& binding, std::span<const std::uint8_t> payload, Nanos now) {
  InboundEvent event;
  event.channel = binding.id;
  event.header.subject = binding.subject;
  event.payload = payload;
  event.received_at = now;
  // What the format carries (none of CAN's carries an event's identity); CAN_RAW never hands a
  // socket its own frames back, so no fingerprint guard either.
  event.identity = binding.format->identity();
  if (sink_) sink_->on_event(event);
}

void CanAdapter::handle_error_frame(const canfd_frame& frame) {
  const canid_t cls = frame.can_id & CAN_ERR_MASK;
  if (cls & CAN_ERR_BUSOFF) {
    set_controller(Controller::bus_off);
    return;
  }
  if (cls & CAN_ERR_RESTARTED) set_controller(Controller::ok);
  if ((cls & CAN_ERR_CRTL) && frame.len >= 2) {
    const std::uint8_t d1 = frame.data[1];
    if (d1 & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++overflow_controller_;
    if (d1 & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      set_controller(Controller::passive);
    } else if (d1 & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      set_controller(Controller::warning);
    } else if (d1 & CAN_ERR_CRTL_ACTIVE) {
      set_controller(Controller::ok);
    }
  }
}

void CanAdapter::handle_get_etag(const canfd_frame& frame, std::size_t len, Nanos now) {
  const auto request =
      can_binding::decode_get_etag(frame.can_id & CAN_EFF_MASK, std::span<const std::uint8_t>(frame.data, len));
  if (!request) {
    problem(kNoChannel, InboundProblem::decode_error);
    return;
  }
  const Table& table = *rx_table_;
  PiLock lock(io_mutex_);
  if (!request_limit_.admit(request->requester, now)) {
    counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
    defer_request(*request);
    return;
  }
  answer_request(*request, table);
}

void CanAdapter::defer_request(const can_binding::GetEtagRequest& request) {
  const bool known = std::any_of(deferred_requests_.begin(), deferred_requests_.end(), [&](const auto& d) {
    return d.requester == request.requester && d.subject == request.subject;
  });
  const bool kept = !known && deferred_requests_.size() < kMaxPendingRequests;
  if (kept) deferred_requests_.push_back(request);
  const std::uint64_t over = refused_requests_.fetch_add(1) + 1;
  if (over % 1000 == 1) {
    log_.log(LogLevel::warning, prefix_ + "GET_ETAG from TxNode " + std::to_string(request.requester) +
                                    " over the rate limit, " +
                                    (kept    ? "answered later"
                                     : known ? "already waiting"
                                             : "deferred queue full, dropped") +
                                    " (" + std::to_string(over) + " over the limit so far)");
  }
}

void CanAdapter::serve_deferred_requests(Nanos now) {
  PiLock lock(io_mutex_);
  if (deferred_requests_.empty()) return;
  const Table& table = *rx_table_;
  std::erase_if(deferred_requests_, [&](const can_binding::GetEtagRequest& r) COSMIC_REQUIRES(io_mutex_) {
    if (!request_limit_.admit(r.requester, now)) return false;
    answer_request(r, table);
    return true;
  });
}

void CanAdapter::answer_request(const can_binding::GetEtagRequest& request, const Table& table) {
  const auto it = table.etag_of.find(request.subject);
  if (it != table.etag_of.end()) {
    queue_supply_etag(request.requester, it->second, request.subject, table);
    return;
  }
  // Unknown subject: no answer. FAMOUSO's client asks only once and waits, so its request is
  // kept (bounded) and answered when a channel with that subject is bound.
  const bool known = std::any_of(pending_requests_.begin(), pending_requests_.end(), [&](const auto& p) {
    return p.requester == request.requester && p.subject == request.subject;
  });
  if (famouso_protocol_ && !known && pending_requests_.size() < kMaxPendingRequests)
    pending_requests_.push_back(request);
}

void CanAdapter::queue_supply_etag(std::uint8_t requester, std::uint16_t etag, std::uint64_t subject,
                                   const Table& table) {
  if (!famouso_protocol_ && !table.tx_node) return;  // no channel bound yet: the gateway has no TxNode here
  const std::uint32_t id =
      famouso_protocol_ ? can_binding::supply_etag_new_bp_id() : can_binding::supply_etag_id(*table.tx_node);
  const auto frames = can_binding::supply_etag_data(requester, etag, subject);
  if (!answers_.room_for(frames.size())) {
    counters_.send_errors.fetch_add(frames.size(), std::memory_order_relaxed);
    return;
  }
  for (const auto& data : frames) queue_answer(id, data);
}

void CanAdapter::queue_answer(std::uint32_t can_id, std::span<const std::uint8_t> data) {
  if (!answers_.room_for(1)) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  can_frame out{};
  out.can_id = can_id | CAN_EFF_FLAG;
  out.len = static_cast<std::uint8_t>(std::min<std::size_t>(data.size(), CAN_MAX_DLEN));
  std::memcpy(out.data, data.data(), out.len);
  answers_.push(out);
  wake();
}

// One answer per call, only when no real-time frame waits in the backlog. Written outside the
// lock like every frame (can_send.cpp); only this thread takes answers out of the queue, so the
// one written is still the queue's first when the result is noted.
void CanAdapter::drain_answers() {
  TxSocketRef socket;
  can_frame answer{};
  Nanos now{0};
  {
    PiLock lock(io_mutex_);
    if (!tx_socket_ || !backlog_.empty() || draining_key_) return;
    now = steady_now();
    const can_frame* due = answers_.due(now);
    if (!due) return;
    answer = *due;
    socket = tx_socket_;
  }
  const ssize_t n = ::write(socket->fd(), &answer, CAN_MTU);
  const int err = n < 0 ? errno : EIO;
  PiLock lock(io_mutex_);
  if (answers_.empty()) return;  // stop() cleared the queue meanwhile
  if (n == static_cast<ssize_t>(CAN_MTU)) {
    counters_.sent.fetch_add(1, std::memory_order_relaxed);
    answers_.sent(now);
    canfd_frame written{};
    std::memcpy(&written, &answer, CAN_MTU);
    tap_sent({&written, 1}, false);
    return;
  }
  if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
    answers_.wait(now);  // the kernel's queue is full: try again one gap later
    return;
  }
  counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
  answers_.sent(now);  // dropped
}

void CanAdapter::handle_protocol_timeouts(Nanos now) {
  if (!ccp_) return;
  if (const auto reset = ccp_->expire(now)) {
    PiLock lock(io_mutex_);
    queue_answer(reset->can_id, reset->data);
  }
}

}  // namespace cosmic::can_detail

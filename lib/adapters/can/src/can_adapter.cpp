#include "can_adapter_impl.hpp"

namespace cosmic::can_detail {

// ------------------------------------------------------------------------------ lifecycle

Status CanAdapter::start(EventSink& sink) {
  if (started_) return Status::failure(prefix_ + "already started");
  if (segment_.can.interface.empty() || segment_.can.interface.size() >= IFNAMSIZ) {
    return Status::failure("invalid CAN interface name '" + segment_.can.interface + "'");
  }
  auto ctl = posix_call("socket(AF_UNIX)", [] { return ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0); });
  if (!ctl) return Status::failure(ctl.error().text);
  ctl_fd_ = ctl.value();
  sink_ = &sink;
  started_ = true;
  secoc_freshness_->attach();
  check_link();  // opens the socket now when the interface is there: health is right at once
  ThreadPolicy policy = sink.receive_thread_policy();
  policy.name = "rx:" + segment_.name;
  if (auto running = receiver_.start(policy, log_, prefix_, [this] { run(); }); !running) {
    close_socket();
    ::close(ctl_fd_);
    ctl_fd_ = -1;
    sink_ = nullptr;
    started_ = false;
    secoc_freshness_->detach();
    return Status::failure(running.error().text);
  }
  return Status::success();
}

void CanAdapter::stop() {
  if (!started_) return;
  receiver_.stop();
  close_socket();
  secoc_freshness_->detach();  // the lanes have stopped sending: the last values persist
  {
    PiLock lock(io_mutex_);
    table_ = std::make_shared<Table>();  // stop() forgets the bindings (SegmentAdapter's lifecycle)
    generation_.fetch_add(1, std::memory_order_release);
    backlog_.clear();
    answers_.clear();
    pending_requests_.clear();
    deferred_requests_.clear();
    backlog_size_ = 0;
    wait_pollout_ = false;
    retry_at_.reset();
  }
  ::close(ctl_fd_);
  ctl_fd_ = -1;
  sink_ = nullptr;
  started_ = false;
  link_up_ = false;
  LockGuard lock(health_mutex_);
  link_ = Link::unknown;
  link_detail_ = "stopped";
  controller_ = Controller::ok;
  shown_ = {SegmentHealth::down, "stopped"};
  health_.set(SegmentHealth::down, "stopped");
}

void CanAdapter::wake() { receiver_.wake(); }

// ------------------------------------------------------------------------------ configure

Status CanAdapter::configure(std::span<const ChannelBinding> bindings) {
  if (!started_) return not_started(segment_.name);
  BindingPlan plan(bindings);
  std::shared_ptr<Table> table = plan_table(plan);
  Status status = plan.status();
  {
    PiLock lock(io_mutex_);
    if (sock_ >= 0 && ::setsockopt(sock_, SOL_CAN_RAW, CAN_RAW_FILTER, table->filters.data(),
                                   static_cast<socklen_t>(table->filters.size() * sizeof(can_filter))) != 0) {
      // The kernel keeps the old filters, so the old table stays: the whole segment failed.
      const std::string error = "CAN_RAW_FILTER: " + errno_text(errno) + "; the previous channels stay";
      log_.log(LogLevel::error, prefix_ + error);
      return Status::failure(error);
    }
    backlog_.set_capacity(table->backlog_frames);
    for (auto it = tx_sequence_.begin(); it != tx_sequence_.end();) {
      const bool bound =
          std::any_of(table->tx.begin(), table->tx.end(), [&](const auto& t) { return t.second.etag == it->first; });
      it = bound ? std::next(it) : tx_sequence_.erase(it);
    }
    // FAMOUSO nodes ask once and wait: requests for subjects bound only now are answered now.
    std::erase_if(pending_requests_, [&](const can_binding::GetEtagRequest& r) COSMIC_REQUIRES(io_mutex_) {
      const auto found = table->etag_of.find(r.subject);
      if (found == table->etag_of.end()) return false;
      queue_supply_etag(r.requester, found->second, r.subject, *table);
      return true;
    });
    table_ = std::move(table);
    generation_.fetch_add(1, std::memory_order_release);
    if (!answers_.empty()) wake();
  }
  if (!status.ok) log_.log(LogLevel::error, prefix_ + status.error);
  return status;
}

std::shared_ptr<CanAdapter::Table> CanAdapter::plan_table(BindingPlan& plan) {
  std::shared_ptr<Table> table = build_table(plan);
  // A channel refused in one role may have entered the table in another: build it again without.
  // Fewer bindings only take reasons to refuse away, so the second build refuses nothing more.
  if (plan.any_refused()) table = build_table(plan);
  return table;
}

std::shared_ptr<CanAdapter::Table> CanAdapter::build_table(BindingPlan& plan) {
  auto table = std::make_shared<Table>();
  for (const CanBackgroundFrame& frame : segment_.can.background) table->native.add_background(frame);
  for (const ChannelBinding* binding : plan.accepted()) {
    const ChannelBinding& b = *binding;
    const Result<void> bound = !b.can          ? Result<void>(Error{"no CAN plan"})
                               : b.can->native ? bind_native(b, *table)
                                               : bind_etag(b, *table);
    if (!bound) plan.refuse(b, bound.error().text);
  }
  if (famouso_protocol_)
    table->etag_of[kFamousoSubscribeSubject] = kEtagFamousoSubscribe;  // FAMOUSO nodes bind it at start
  // Kernel filters: the 14 etag bits of every etag bound as publisher, plus the protocols' etags;
  // extended frames only. Everything else stays in the kernel.
  table->filters = protocol_filters(famouso_protocol_);
  const std::vector<can_filter> native_filters = table->native.filters();
  if (table->rx.size() + native_filters.size() + table->filters.size() <= CAN_RAW_FILTER_MAX) {
    for (const auto& [etag, channel] : table->rx)
      table->filters.push_back(can_filter{etag | CAN_EFF_FLAG, kEtagFilterMask});
    table->filters.insert(table->filters.end(), native_filters.begin(), native_filters.end());
  } else {
    table->filters.assign(1, can_filter{0, 0});  // too many: every frame, filtered in user space
  }

  return table;
}

CanFrameFormat& CanAdapter::format_of(const CanHopPlan& plan) {
  if (plan.native) return native_frames_;
  return plan.profile == CanProfile::famouso ? static_cast<CanFrameFormat&>(famouso_frames_) : cosmic_frames_;
}

Result<void> CanAdapter::bind_native(const ChannelBinding& b, Table& table) {
  if (Result<void> fits = native_frames_.check_payload(b.spec.payload_on(segment_.name)); !fits) return fits;
  const NativeCanFrame frame{b.can->can_id, b.can->extended};
  const auto payload = static_cast<std::size_t>(b.spec.payload_on(segment_.name));
  const canid_t identifier = frame.can_id | (frame.extended ? CAN_EFF_FLAG : 0);
  auto secoc = bind_secoc(b, identifier);
  if (!secoc) return secoc.error();
  if (b.role == HopRole::publisher) {
    if (!table.native.add_publisher(frame, can_native::RxChannel{b.id, b.spec.subject, payload, secoc.value().rx})) {
      return Error{"native identifier bound twice as publisher"};
    }
  } else {
    table.tx[b.id] = CanTxBinding{b.id, &native_frames_, frame.can_id, frame.can_id,    frame.extended,
                                  0,    payload,         false,        secoc.value().tx};
    table.native.add_subscriber(frame);
  }
  return {};
}

Result<void> CanAdapter::bind_etag(const ChannelBinding& b, Table& table) {
  // The binding protocol (who hands out etags and TxNodes) is the segment's: a binding in the
  // other layout would reach nodes that cannot bind it.
  if (b.can->profile != segment_.can.profile) {
    return Error{"the plan is for another identifier layout than the segment's profile"};
  }
  const std::uint16_t etag = b.can->etag;
  if (etag <= kHighestReservedEtag || etag > kMaxEtag)
    return Error{"etag " + std::to_string(etag) + " is reserved or out of range"};
  CanFrameFormat& format = format_of(*b.can);
  if (Result<void> fits = format.check_payload(b.spec.payload_on(segment_.name)); !fits) return fits;
  const bool fragmented = format.fragments(b.spec.payload_on(segment_.name));
  const CanIdentifier id = decode_can_id(b.can->can_id & CAN_EFF_MASK);
  const auto payload = static_cast<std::size_t>(b.spec.payload_on(segment_.name));
  // A publisher hop's plan names the nodes' identifier; the data ID then comes from each frame's.
  auto secoc = bind_secoc(b, (b.can->can_id & CAN_EFF_MASK) | CAN_EFF_FLAG);
  if (!secoc) return secoc.error();
  if (secoc.value().tx || secoc.value().rx) {
    if (b.can->profile == CanProfile::famouso) return Error{"SecOC needs this project's layout, not FAMOUSO's"};
  }
  if (b.role == HopRole::publisher) {
    if (!table.rx.emplace(etag, CanRxBinding{b.id, &format, b.spec.subject, payload, fragmented, secoc.value().rx})
             .second) {
      return Error{"etag " + std::to_string(etag) + " bound twice as publisher"};
    }
  } else {
    // Admission's identifier, in the segment's layout. FAMOUSO: a single frame goes without the
    // fragment flag, AFP fragments with it (admission planned the flag of the channel's largest events).
    const std::uint32_t planned = b.can->can_id & CAN_EFF_MASK;
    const bool famouso = b.can->profile == CanProfile::famouso;
    const CanTxBinding tx{b.id,
                          &format,
                          famouso ? planned & ~kFamousoFragmentFlag : planned,
                          famouso ? planned | kFamousoFragmentFlag : planned,
                          true,
                          etag,
                          payload,
                          fragmented,
                          secoc.value().tx};
    table.tx[b.id] = tx;
    table.tx_etags.insert(etag);
    if (fragmented) table.backlog_frames = std::max(table.backlog_frames, 2 * format.frame_count(tx, payload));
    if (!table.tx_node) table.tx_node = id.tx_node;
  }
  table.etag_of[b.spec.subject] = etag;
  // FAMOUSO: a publisher hop's plan carries the nodes' TxNode, not the gateway's.
  if (!famouso_protocol_ && !table.tx_node) table.tx_node = id.tx_node;
  return {};
}

void CanAdapter::refresh_rx_table() {
  const std::uint64_t generation = generation_.load(std::memory_order_acquire);
  if (generation != rx_generation_) {
    PiLock lock(io_mutex_);
    rx_table_ = table_;
    rx_generation_ = generation;
  }
}

// ------------------------------------------------------------------------------ health

void CanAdapter::update_health() {
  HealthReport next;
  const std::string& ifname = segment_.can.interface;
  if (link_ != Link::up) {
    next = {SegmentHealth::down, link_detail_};
  } else if (controller_ == Controller::bus_off) {
    next = {SegmentHealth::down, "bus-off on " + ifname};
  } else if (controller_ == Controller::passive) {
    next = {SegmentHealth::degraded, "controller of " + ifname + " is error-passive"};
  } else if (controller_ == Controller::warning) {
    next = {SegmentHealth::degraded, "controller of " + ifname + " reached the error warning level"};
  } else {
    next = {SegmentHealth::up, ""};
  }
  if (next.state == shown_.state && next.detail == shown_.detail) return;
  shown_ = next;
  health_.set(next.state, next.detail);
  if (next.state == SegmentHealth::up) {
    log_.log(LogLevel::notice, prefix_ + "interface " + ifname + " is up");
  } else {
    log_.log(LogLevel::warning, prefix_ + std::string(to_string(next.state)) + ": " + next.detail);
  }
}

void CanAdapter::set_link(Link link, std::string detail) {
  bool went_down = false;
  bool came_up = false;
  {
    LockGuard lock(health_mutex_);
    went_down = link != Link::up && link_ == Link::up;
    came_up = link == Link::up && link_ != Link::up;
    link_ = link;
    link_detail_ = std::move(detail);
    if (came_up) controller_ = Controller::ok;  // a restarted interface starts error-active
    update_health();
  }
  link_up_ = link == Link::up;
  if (went_down || (link != Link::up && backlog_size_ > 0)) {
    std::string dropped;
    {
      PiLock lock(io_mutex_);
      dropped = drop_backlog("interface not up");
    }
    log_unlocked(dropped);
  }
  if (came_up || went_down) {
    cosmic_frames_.clear();
    famouso_frames_.clear();
  }
  if (came_up) {
    PiLock lock(io_mutex_);
    send_error_logged_ = false;
  }
}

void CanAdapter::set_controller(Controller state) {
  LockGuard lock(health_mutex_);
  controller_ = state;
  update_health();
}

HealthReport CanAdapter::health() const { return health_.get(); }

AdapterStatistics CanAdapter::statistics() const {
  AdapterStatistics s = counters_.snapshot();
  // The kernel's drops: the closed sockets', the open socket's and the controller's.
  s.overflow_drops = overflow_closed_.load() + overflow_socket_.load() + overflow_controller_.load();
  s.backlog = backlog_size_.load();
  s.transport.push_back(TransportCounter{"binding_requests_over_limit", refused_requests_.load()});
  if (secoc_bound_.load(std::memory_order_relaxed)) {
    s.transport.push_back(TransportCounter{"unauthenticated", secoc_unauthenticated_.load()});
    s.transport.push_back(TransportCounter{"replayed", secoc_replayed_.load()});
  }
  s.unexplained = census_.snapshot(steady_now());
  s.unexplained_others = census_.others();
  return s;
}

}  // namespace cosmic::can_detail

namespace cosmic {

std::unique_ptr<SegmentAdapter> make_can_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log,
                                                 CanAdapterOptions options) {
  (void)self;  // CAN frames carry no envelope: the gateway is known by its TxNode
  return std::make_unique<can_detail::CanAdapter>(segment, log, std::move(options.secoc), std::move(options.tap));
}

CanSecocState make_can_secoc_state(std::string file, const std::string& segment, Logger& log) {
  return std::make_shared<can_detail::SecocFreshness>(std::move(file), segment_log_prefix(SegmentType::can, segment),
                                                      "fv:" + segment, log);
}

}  // namespace cosmic

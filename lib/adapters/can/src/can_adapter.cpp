#include "cosmic/can_adapter.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "binding_guard.hpp"
#include "can_binding.hpp"
#include "cosmic/arrival_clock.hpp"
#include "cosmic/thread_policy.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"
#include "famouso_afp.hpp"
#include "famouso_ccp.hpp"
#include "frame_backlog.hpp"
#include "bus_census.hpp"
#include "native_frames.hpp"

namespace cosmic {
namespace {

using std::chrono::milliseconds;

constexpr std::size_t kMinBacklogFrames = 256;
constexpr std::size_t kMaxPartialEvents = 32;
// Idle time after which a partial event is dropped. NRT fragments have the lowest priorities and
// may wait long on a loaded bus; memory stays bounded by kMaxPartialEvents either way.
constexpr Nanos kReassemblyTimeout = milliseconds(1000);
constexpr Nanos kLinkCheckWhileDown = milliseconds(200);
constexpr Nanos kLinkCheckWhileUp = milliseconds(1000);
constexpr Nanos kEnobufsRetry = milliseconds(1);
constexpr int kFramesPerWakeup = 256;
constexpr std::size_t kReadBatch = 32;  // frames per recvmmsg
constexpr std::size_t kFdPaddingSlack = 15;  // 48 -> 64 is the largest step between FD lengths
constexpr can_err_mask_t kErrorMask = CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
constexpr Nanos kDeferredRequestRetry = std::chrono::milliseconds(20);  // well below one token (100 ms)
constexpr std::size_t kMaxPendingRequests = 64;     // FAMOUSO: unanswered GET_ETAGs kept for a later bind
constexpr std::size_t kMaxAnnouncedSubscriptions = 256;  // FAMOUSO: subscriptions logged once each
constexpr canid_t kEtagFilterMask = 0x3FFF | CAN_EFF_FLAG;

Nanos steady_now() { return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()); }

std::string errno_text(int err) { return std::strerror(err); }

std::uint32_t source_key(const CanIdentifier& id) { return (static_cast<std::uint32_t>(id.tx_node) << 14) | id.etag; }

// Binding answers leave one at a time, two frame times apart (an extended 8-byte frame is at
// most 160 bits with stuffing), so at most one is in the kernel's FIFO ahead of a real-time frame.
Nanos answer_gap(const CanSegmentProperties& can) {
  const double bits = 2 * 160.0;
  const double rate = static_cast<double>(std::max<std::uint64_t>(can.bitrate.bits_per_second, 10'000));
  return std::max(Nanos(200'000), Nanos(static_cast<std::int64_t>(bits * 1e9 / rate)));
}

// Etags the socket receives whatever is bound: the binding protocol, and on a FAMOUSO segment
// the configuration protocol and the SUBSCRIBE announcements.
std::vector<can_filter> protocol_filters(bool famouso) {
  std::vector<can_filter> f{can_filter{kEtagGetEtag | CAN_EFF_FLAG, kEtagFilterMask}};
  if (famouso) {
    f.push_back(can_filter{kEtagCcpRsi | CAN_EFF_FLAG, kEtagFilterMask});
    f.push_back(can_filter{kEtagFamousoSubscribe | CAN_EFF_FLAG, kEtagFilterMask});
  }
  return f;
}

class CanAdapter final : public SegmentAdapter {
 public:
  CanAdapter(const SegmentSpec& segment, Logger& log)
      : segment_(segment),
        log_(log),
        capacity_(max_frame_payload(segment.can)),
        brs_(segment.can.fd && segment.can.data_bitrate > segment.can.bitrate),
        famouso_(segment.can.profile == CanProfile::famouso),
        reassembler_(ReassemblyLimits{kMaxPartialEvents, kReassemblyTimeout, segment.can.fd ? kFdPaddingSlack : 0}),
        afp_(famouso::AfpLimits{kMaxPartialEvents, kReassemblyTimeout}),
        ccp_(segment.can.profile == CanProfile::famouso ? std::optional<famouso::CcpBroker>(std::in_place)
                                                        : std::nullopt),
        table_(std::make_shared<const Table>()),
        answers_(answer_gap(segment.can)) {}

  ~CanAdapter() override { stop(); }

  Status start(EventSink& sink) override;
  Status configure(std::span<const ChannelBinding> bindings) override;
  SendStatus send(const OutboundEvent& event) override;
  HealthReport health() const override;
  AdapterStatistics statistics() const override;
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }  // broadcast bus
  void stop() override;

 private:
  struct RxChannel {
    ChannelId id = kNoChannel;
    std::uint64_t subject = 0;
    std::size_t payload = 0;
    bool fragmented = false;
  };
  struct TxChannel {
    ChannelId id = kNoChannel;
    std::uint32_t can_id = 0;  // 29 bits, in the segment's profile
    std::uint32_t afp_id = 0;  // FAMOUSO: the identifier with the fragment flag
    std::uint16_t etag = 0;
    std::size_t payload = 0;
    bool fragmented = false;
    std::optional<NativeCanFrame> native;  // a native channel: this frame, no etag (native_frames.hpp)
  };
  struct Table {
    std::unordered_map<std::uint16_t, RxChannel> rx;           // etag -> channel bound as publisher
    std::unordered_map<ChannelId, TxChannel> tx;               // channels bound as subscriber
    std::unordered_map<std::uint64_t, std::uint16_t> etag_of;  // subject -> etag, both roles
    can_native::FrameTable native;                             // native channels, background frames
    std::unordered_set<std::uint16_t> tx_etags;                // etags of the channels bound as subscriber
    std::optional<std::uint8_t> tx_node;                       // the gateway's TxNode on this bus
    std::vector<can_filter> filters;
    std::size_t backlog_frames = kMinBacklogFrames;
  };

  enum class Link { unknown, up, down };
  enum class Controller { ok, warning, passive, bus_off };

  enum class WriteResult { written, queued, full, failed };

  // --- receive thread
  void run();
  void check_link();
  bool open_socket(int ifindex);
  void close_socket();
  void read_frames();
  // The census socket (bus_census.hpp): every frame on the bus, counted when nothing explains it.
  void open_census_socket(int ifindex);
  void read_census();
  bool explains(const Table& table, canid_t can_id) const;
  void handle_read_error(int err);
  void handle_datagram(canfd_frame& frame, msghdr& msg, std::size_t bytes);
  void handle_frame(const canfd_frame& frame, bool fd_frame, Nanos now);
  void handle_error_frame(const canfd_frame& frame);
  void handle_get_etag(const canfd_frame& frame, std::size_t len, Nanos now);
  void answer_request(const can_binding::GetEtagRequest& request, const Table& table);  // io_mutex_ held
  void defer_request(const can_binding::GetEtagRequest& request);                      // io_mutex_ held
  void serve_deferred_requests(Nanos now);
  void reassembly_losses(ChannelId channel, std::optional<std::uint32_t> displaced, bool lost);
  void handle_famouso_protocol(const CanIdentifier& id, const canfd_frame& frame, std::size_t len, Nanos now);
  void handle_afp(const RxChannel& channel, const CanIdentifier& id, std::span<const std::uint8_t> data, Nanos now);
  void handle_protocol_timeouts(Nanos now);
  void deliver(const RxChannel& channel, std::span<const std::uint8_t> payload, Nanos now);
  void deliver_native(const can_native::RxChannel& channel, std::span<const std::uint8_t> data, bool fd_frame, Nanos now);
  void problem(ChannelId channel, InboundProblem what);
  void drain_backlog();
  void refresh_rx_table();  // the receive thread's snapshot of the bindings (rx_table_)
  // configure(): a native channel's binding into `table`; the reason when it cannot be carried.
  std::optional<std::string> bind_native(const ChannelBinding& b, Table& table) const;
  SendStatus send_frame(const canfd_frame& frame);  // io_mutex_ held

  // --- health
  void set_link(Link link, std::string detail);
  void set_controller(Controller state);
  void update_health();  // health_mutex_ held

  // --- send side (io_mutex_ held)
  WriteResult submit(const canfd_frame& frame, bool fd);
  void queue_answer(std::uint32_t can_id, std::span<const std::uint8_t> data);
  void queue_supply_etag(std::uint8_t requester, std::uint16_t etag, std::uint64_t subject, const Table& table);
  void drain_answers();
  SendStatus send_afp(const TxChannel& channel, std::span<const std::uint8_t> payload, std::unique_lock<std::mutex>& lock);
  void wake();
  void drop_backlog(const char* why);

  const SegmentSpec segment_;
  Logger& log_;
  const std::uint32_t capacity_;  // data bytes of one frame on this bus
  const bool brs_;
  const bool famouso_;  // FAMOUSO profile: its identifier layout, CCP, etag-4 answers, AFP

  EventSink* sink_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> started_{false};
  int wake_fd_ = -1;
  int ctl_fd_ = -1;  // for interface ioctls (AF_UNIX: works without AF_CAN)

  // Receive-thread state.
  Reassembler reassembler_;
  famouso::AfpReassembler afp_;
  std::optional<famouso::CcpBroker> ccp_;  // FAMOUSO segments only
  std::vector<std::pair<std::uint8_t, std::uint64_t>> announced_;  // FAMOUSO subscriptions seen (node, subject)
  std::shared_ptr<const Table> rx_table_;
  std::uint64_t rx_generation_ = ~0ull;
  int bound_ifindex_ = 0;
  Nanos next_link_check_{0};

  // Socket and send side. The receive thread opens and closes the socket (holding io_mutex_);
  // send(), configure() and the receive thread write through it holding io_mutex_.
  mutable std::mutex io_mutex_;
  int sock_ = -1;
  int census_sock_ = -1;  // only the receive thread opens, reads and closes it
  bool census_error_logged_ = false;
  std::shared_ptr<const Table> table_;
  std::atomic<std::uint64_t> generation_{0};
  FrameBacklog backlog_;
  ProtocolQueue answers_;  // binding and CCP answers: after the backlog, paced
  BindingRateLimit request_limit_;
  std::vector<can_binding::GetEtagRequest> pending_requests_;  // FAMOUSO: unknown subjects, answered on bind
  // Requests over the rate limit, answered when the node's budget allows: a client that asks
  // once (FAMOUSO's) must not lose its binding to a burst at start-up. One entry per (node,
  // subject), bounded, so a flood costs a counter and at most one later answer.
  std::deque<can_binding::GetEtagRequest> deferred_requests_;
  std::atomic<std::uint64_t> refused_requests_{0};  // over the rate limit (deferred or dropped)
  std::unordered_map<std::uint16_t, std::uint8_t> tx_sequence_;
  bool wait_pollout_ = false;      // backlog waits for POLLOUT (EAGAIN)
  std::optional<Nanos> retry_at_;  // backlog waits for the qdisc (ENOBUFS)
  bool send_error_logged_ = false;
  std::atomic<bool> link_up_{false};

  // Health.
  mutable std::mutex health_mutex_;
  Link link_ = Link::unknown;
  std::string link_detail_ = "not started";
  Controller controller_ = Controller::ok;
  HealthReport health_{SegmentHealth::down, "not started"};

  // Statistics.
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> receive_errors_{0};
  std::atomic<std::uint64_t> send_errors_{0};
  std::atomic<std::uint64_t> overflow_closed_{0};  // SO_RXQ_OVFL of sockets already closed
  std::atomic<std::uint64_t> overflow_socket_{0};  // SO_RXQ_OVFL of the open socket
  std::atomic<std::uint64_t> overflow_controller_{0};
  std::atomic<std::uint64_t> backlog_size_{0};
  can_census::BusCensus census_;
};

// ------------------------------------------------------------------------------ lifecycle

Status CanAdapter::start(EventSink& sink) {
  if (started_) return Status::failure("already started");
  if (segment_.can.interface.empty() || segment_.can.interface.size() >= IFNAMSIZ) {
    return Status::failure("invalid CAN interface name '" + segment_.can.interface + "'");
  }
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) return Status::failure("eventfd: " + errno_text(errno));
  ctl_fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (ctl_fd_ < 0) {
    const int err = errno;
    ::close(wake_fd_);
    wake_fd_ = -1;
    return Status::failure("socket(AF_UNIX): " + errno_text(err));
  }
  sink_ = &sink;
  stopping_ = false;
  started_ = true;
  check_link();  // opens the socket now when the interface is there: health is right at once
  try {
    ThreadPolicy policy = sink.receive_thread_policy();
    policy.name = "rx:" + segment_.name;
    thread_ = std::thread([this, policy] {
      for (const auto& problem : apply_thread_policy(policy))
        log_.log(LogLevel::warning, "segment " + segment_.name + ": receive thread: " + problem);
      run();
    });
  } catch (const std::exception& e) {
    close_socket();
    ::close(ctl_fd_);
    ::close(wake_fd_);
    ctl_fd_ = wake_fd_ = -1;
    started_ = false;
    return Status::failure(std::string("cannot start the receive thread: ") + e.what());
  }
  return Status::success();
}

void CanAdapter::stop() {
  if (!started_) return;
  stopping_ = true;
  wake();
  if (thread_.joinable()) thread_.join();
  close_socket();
  {
    std::lock_guard lock(io_mutex_);
    backlog_.clear();
    answers_.clear();
    pending_requests_.clear();
    deferred_requests_.clear();
    backlog_size_ = 0;
    wait_pollout_ = false;
    retry_at_.reset();
  }
  ::close(ctl_fd_);
  ::close(wake_fd_);
  ctl_fd_ = wake_fd_ = -1;
  sink_ = nullptr;
  started_ = false;
  link_up_ = false;
  std::lock_guard lock(health_mutex_);
  link_ = Link::unknown;
  link_detail_ = "stopped";
  controller_ = Controller::ok;
  health_ = {SegmentHealth::down, "stopped"};
}

void CanAdapter::wake() {
  if (wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
}

// ------------------------------------------------------------------------------ configure

Status CanAdapter::configure(std::span<const ChannelBinding> bindings) {
  auto table = std::make_shared<Table>();
  std::string errors;
  auto refuse = [&](const ChannelBinding& b, const std::string& why) {
    errors += (errors.empty() ? "" : "; ") + ("channel " + b.spec.name + ": " + why);
  };
  for (const CanBackgroundFrame& frame : segment_.can.background) table->native.add_background(frame);
  for (const auto& b : bindings) {
    if (!b.can) {
      refuse(b, "no CAN plan");
      continue;
    }
    if (b.can->native) {
      if (const auto why = bind_native(b, *table)) refuse(b, *why);
      continue;
    }
    if (b.can->profile != segment_.can.profile) {
      refuse(b, "the plan is for another identifier layout than the segment's profile");
      continue;
    }
    const std::uint16_t etag = b.can->etag;
    if (etag <= kHighestReservedEtag || etag > kMaxEtag) {
      refuse(b, "etag " + std::to_string(etag) + " is reserved or out of range");
      continue;
    }
    const bool fragmented = needs_fragmentation(b.spec.payload, capacity_);
    if (fragmented && b.spec.payload > max_fragmented_event(capacity_)) {
      refuse(b, "payload " + std::to_string(b.spec.payload) + " B exceeds " +
                    std::to_string(max_fragmented_event(capacity_)) + " B (" + std::to_string(kMaxFragments) +
                    " fragments)");
      continue;
    }
    const CanIdentifier id = decode_can_id(b.can->can_id & CAN_EFF_MASK);
    const auto payload = static_cast<std::size_t>(b.spec.payload);
    if (b.role == HopRole::publisher) {
      if (!table->rx.emplace(etag, RxChannel{b.id, b.spec.subject, payload, fragmented}).second) {
        refuse(b, "etag " + std::to_string(etag) + " bound twice as publisher");
        continue;
      }
    } else {
      // Admission's identifier, in the segment's layout. FAMOUSO: a single frame goes without
      // the fragment flag, AFP fragments with it (admission planned the flag of the channel's
      // largest events).
      const std::uint32_t planned = b.can->can_id & CAN_EFF_MASK;
      const std::uint32_t can_id = famouso_ ? planned & ~kFamousoFragmentFlag : planned;
      table->tx[b.id] = TxChannel{b.id, can_id, planned | kFamousoFragmentFlag, etag, payload, fragmented, std::nullopt};
      table->tx_etags.insert(etag);
      if (fragmented) {
        const std::size_t frames = famouso_ ? famouso::afp_fragment_count(payload) : fragment_count(payload, capacity_);
        table->backlog_frames = std::max<std::size_t>(table->backlog_frames, 2 * frames);
      }
      if (!table->tx_node) table->tx_node = id.tx_node;
    }
    table->etag_of[b.spec.subject] = etag;
    // FAMOUSO: a publisher hop's plan carries the nodes' TxNode, not the gateway's.
    if (!famouso_ && !table->tx_node) table->tx_node = id.tx_node;
  }
  if (famouso_) table->etag_of[kFamousoSubscribeSubject] = kEtagFamousoSubscribe;  // FAMOUSO nodes bind it at start
  // Kernel filters: the 14 etag bits of every etag bound as publisher, plus the protocols' etags;
  // extended frames only. Everything else stays in the kernel.
  table->filters = protocol_filters(famouso_);
  const std::vector<can_filter> native_filters = table->native.filters();
  if (table->rx.size() + native_filters.size() + table->filters.size() <= CAN_RAW_FILTER_MAX) {
    for (const auto& [etag, channel] : table->rx) table->filters.push_back(can_filter{etag | CAN_EFF_FLAG, kEtagFilterMask});
    table->filters.insert(table->filters.end(), native_filters.begin(), native_filters.end());
  } else {
    table->filters.assign(1, can_filter{0, 0});  // too many: every frame, filtered in user space
  }

  std::lock_guard lock(io_mutex_);
  if (sock_ >= 0 && ::setsockopt(sock_, SOL_CAN_RAW, CAN_RAW_FILTER, table->filters.data(),
                                 static_cast<socklen_t>(table->filters.size() * sizeof(can_filter))) != 0) {
    errors += (errors.empty() ? "" : "; ") + ("CAN_RAW_FILTER: " + errno_text(errno));
  }
  backlog_.set_capacity(table->backlog_frames);
  for (auto it = tx_sequence_.begin(); it != tx_sequence_.end();) {
    const bool bound =
        std::any_of(table->tx.begin(), table->tx.end(), [&](const auto& t) { return t.second.etag == it->first; });
    it = bound ? std::next(it) : tx_sequence_.erase(it);
  }
  // FAMOUSO nodes ask once and wait: requests for subjects bound only now are answered now.
  std::erase_if(pending_requests_, [&](const can_binding::GetEtagRequest& r) {
    const auto found = table->etag_of.find(r.subject);
    if (found == table->etag_of.end()) return false;
    queue_supply_etag(r.requester, found->second, r.subject, *table);
    return true;
  });
  table_ = std::move(table);
  generation_.fetch_add(1, std::memory_order_release);
  if (!answers_.empty()) wake();
  if (!errors.empty()) {
    log_.log(LogLevel::error, "segment " + segment_.name + ": " + errors);
    return Status::failure(errors);
  }
  return Status::success();
}

std::optional<std::string> CanAdapter::bind_native(const ChannelBinding& b, Table& table) const {
  if (b.spec.payload > capacity_) {
    return "payload " + std::to_string(b.spec.payload) + " B does not fit one native frame (" + std::to_string(capacity_) + " B)";
  }
  const NativeCanFrame frame{b.can->can_id, b.can->extended};
  const auto payload = static_cast<std::size_t>(b.spec.payload);
  if (b.role == HopRole::publisher) {
    if (!table.native.add_publisher(frame, can_native::RxChannel{b.id, b.spec.subject, payload})) {
      return "native identifier bound twice as publisher";
    }
  } else {
    table.tx[b.id] = TxChannel{b.id, 0, 0, 0, payload, false, frame};
    table.native.add_subscriber(frame);
  }
  return std::nullopt;
}

void CanAdapter::refresh_rx_table() {
  const std::uint64_t generation = generation_.load(std::memory_order_acquire);
  if (generation != rx_generation_) {
    std::lock_guard lock(io_mutex_);
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
  if (next.state == health_.state && next.detail == health_.detail) return;
  health_ = next;
  const std::string prefix = "segment " + segment_.name + ": ";
  if (next.state == SegmentHealth::up) {
    log_.log(LogLevel::notice, prefix + "interface " + ifname + " is up");
  } else {
    log_.log(LogLevel::warning, prefix + std::string(to_string(next.state)) + ": " + next.detail);
  }
}

void CanAdapter::set_link(Link link, std::string detail) {
  bool went_down = false;
  bool came_up = false;
  {
    std::lock_guard lock(health_mutex_);
    went_down = link != Link::up && link_ == Link::up;
    came_up = link == Link::up && link_ != Link::up;
    link_ = link;
    link_detail_ = std::move(detail);
    if (came_up) controller_ = Controller::ok;  // a restarted interface starts error-active
    update_health();
  }
  link_up_ = link == Link::up;
  if (went_down || (link != Link::up && backlog_size_ > 0)) {
    std::lock_guard lock(io_mutex_);
    drop_backlog("interface not up");
  }
  if (came_up || went_down) {
    reassembler_.clear();
    afp_.clear();
  }
  if (came_up) {
    std::lock_guard lock(io_mutex_);
    send_error_logged_ = false;
  }
}

void CanAdapter::set_controller(Controller state) {
  std::lock_guard lock(health_mutex_);
  controller_ = state;
  update_health();
}

HealthReport CanAdapter::health() const {
  std::lock_guard lock(health_mutex_);
  return health_;
}

AdapterStatistics CanAdapter::statistics() const {
  AdapterStatistics s;
  s.received = received_.load();
  s.sent = sent_.load();
  s.receive_errors = receive_errors_.load();
  s.send_errors = send_errors_.load();
  s.overflow_drops = overflow_closed_.load() + overflow_socket_.load() + overflow_controller_.load();
  s.backlog = backlog_size_.load();
  s.binding_requests_over_limit = refused_requests_.load();
  s.unexplained = census_.snapshot(steady_now());
  s.unexplained_others = census_.others();
  return s;
}

// ------------------------------------------------------------------------------ socket and link

void CanAdapter::close_socket() {
  if (census_sock_ >= 0) {
    ::close(census_sock_);
    census_sock_ = -1;
  }
  std::lock_guard lock(io_mutex_);
  if (sock_ < 0) return;
  ::close(sock_);
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

  // Filters go on before bind: no frame of an unbound etag is ever queued to this socket. A
  // configure() racing with this is caught below by the generation check.
  std::uint64_t generation = 0;
  for (;;) {
    std::vector<can_filter> filters;
    {
      std::lock_guard lock(io_mutex_);
      generation = generation_.load();
      filters = table_->filters;
    }
    if (filters.empty()) filters = protocol_filters(famouso_);
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0) {
      return fail("CAN_RAW_FILTER");
    }
    std::lock_guard lock(io_mutex_);
    if (generation == generation_.load()) break;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifindex;
  if (::bind(s, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) return fail("bind");
  std::lock_guard lock(io_mutex_);
  if (generation != generation_.load() &&
      ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, table_->filters.data(),
                   static_cast<socklen_t>(table_->filters.size() * sizeof(can_filter))) != 0) {
    const int err = errno;
    ::close(s);
    log_.log(LogLevel::error, "segment " + segment_.name + ": CAN_RAW_FILTER: " + errno_text(err));
    return false;
  }
  if (sock_ >= 0) {
    ::close(sock_);
    overflow_closed_ += overflow_socket_.exchange(0);
  }
  sock_ = s;
  bound_ifindex_ = ifindex;
  wait_pollout_ = false;
  open_census_socket(ifindex);
  return true;
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
  const bool ok = s >= 0 && (!segment_.can.fd || ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) == 0) &&
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
    log_.log(LogLevel::warning, "segment " + segment_.name + ": no census socket (unexplained frames are not counted): " + errno_text(err));
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
    std::lock_guard lock(io_mutex_);
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
  while (!stopping_) {
    Nanos now = steady_now();
    if (now >= next_link_check_) {
      check_link();
      now = steady_now();
      next_link_check_ = now + (link_up_ ? kLinkCheckWhileUp : kLinkCheckWhileDown);
    }
    refresh_rx_table();
    reassembler_.expire(now, [this](std::uint32_t source) { reassembly_losses(kNoChannel, source, false); });
    handle_protocol_timeouts(now);
    serve_deferred_requests(now);

    pollfd fds[3] = {{wake_fd_, POLLIN, 0}, {-1, 0, 0}, {census_sock_, POLLIN, 0}};
    Nanos deadline = next_link_check_;
    if (const auto d = reassembler_.next_deadline()) deadline = std::min(deadline, *d + Nanos(1));
    if (const auto d = afp_.next_deadline()) deadline = std::min(deadline, *d + Nanos(1));
    if (const auto d = ccp_ ? ccp_->deadline() : std::nullopt) deadline = std::min(deadline, *d);
    {
      std::lock_guard lock(io_mutex_);
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
      log_.log(LogLevel::error, "segment " + segment_.name + ": poll: " + errno_text(errno));
      std::this_thread::sleep_for(milliseconds(10));
      continue;
    }
    if (stopping_) break;
    if (fds[0].revents & POLLIN) {
      std::uint64_t count = 0;
      [[maybe_unused]] const ssize_t n = ::read(wake_fd_, &count, sizeof count);
    }
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
  const int s = sock_;  // only this thread changes sock_
  constexpr std::size_t kControlBytes = CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t));
  struct Slot {
    canfd_frame frame;
    iovec iov;
    alignas(cmsghdr) char control[kControlBytes];
  };
  std::array<Slot, kReadBatch> slots;
  std::array<mmsghdr, kReadBatch> messages;
  for (int round = 0; round < kFramesPerWakeup / static_cast<int>(kReadBatch) && s >= 0 && sock_ == s; ++round) {
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
  ++receive_errors_;
  log_.log(LogLevel::warning, "segment " + segment_.name + ": recvmmsg: " + errno_text(err));
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
  if (bytes == CAN_MTU) {
    frame.flags = 0;  // the byte is padding in struct can_frame
    handle_frame(frame, false, arrival);
  } else if (bytes == CANFD_MTU) {
    handle_frame(frame, true, arrival);
  } else {
    problem(kNoChannel, InboundProblem::decode_error);
  }
}

void CanAdapter::problem(ChannelId channel, InboundProblem what) {
  ++receive_errors_;
  if (sink_) sink_->on_problem(channel, what);
}

void CanAdapter::handle_frame(const canfd_frame& frame, bool fd_frame, Nanos now) {
  if (frame.can_id & CAN_ERR_FLAG) {
    handle_error_frame(frame);
    return;
  }
  ++received_;
  const std::size_t len = std::min<std::size_t>(frame.len, fd_frame ? CANFD_MAX_DLEN : CAN_MAX_DLEN);
  refresh_rx_table();
  const Table& table = *rx_table_;
  // Native identifiers first: an extended one may have any bits in the etag field.
  if (const can_native::RxChannel* native = table.native.find(frame.can_id)) {
    deliver_native(*native, std::span<const std::uint8_t>(frame.data, len), fd_frame, now);
    return;
  }
  if (table.native.is_background(frame.can_id)) return;  // another device's declared frame
  if (!(frame.can_id & CAN_EFF_FLAG)) {  // an 11-bit frame: not ours (only without kernel filters)
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
  if (famouso_ && (id.etag == kEtagCcpRsi || id.etag == kEtagFamousoSubscribe)) {
    handle_famouso_protocol(id, frame, len, now);
    return;
  }
  const auto it = table.rx.find(id.etag);
  if (it == table.rx.end()) {
    problem(kNoChannel, InboundProblem::unknown_channel);
    return;
  }
  const RxChannel& channel = it->second;
  if (frame.can_id & CAN_RTR_FLAG) {
    problem(channel.id, InboundProblem::decode_error);
    return;
  }
  const std::span<const std::uint8_t> data(frame.data, len);
  if (famouso_ && decode_famouso_id(frame.can_id & CAN_EFF_MASK).fragment) {
    handle_afp(channel, id, data, now);
    return;
  }
  if (!channel.fragmented || famouso_) {  // FAMOUSO: events of up to 8 bytes are plain frames
    // A device may send shorter events; on CAN FD the frame may carry padding up to the next
    // FD length, which is cut off at the channel's payload.
    const std::size_t allowed =
        fd_frame ? fd_padded_length(static_cast<std::uint32_t>(channel.payload)) : channel.payload;
    if (len > allowed) {
      problem(channel.id, InboundProblem::decode_error);
      return;
    }
    deliver(channel, data.first(std::min(len, channel.payload)), now);
    return;
  }
  const FragmentResult r = reassembler_.accept(source_key(id), data, channel.payload, now);
  reassembly_losses(channel.id, r.displaced, r.dropped_event || r.outcome == FragmentOutcome::rejected);
  if (r.outcome == FragmentOutcome::complete) deliver(channel, r.event, now);
}

void CanAdapter::handle_afp(const RxChannel& channel, const CanIdentifier& id, std::span<const std::uint8_t> data,
                            Nanos now) {
  const famouso::AfpResult r = afp_.accept(source_key(id), data, channel.payload, now);
  reassembly_losses(channel.id, r.displaced, r.dropped_event || r.outcome == famouso::AfpOutcome::rejected);
  if (r.outcome == famouso::AfpOutcome::complete) deliver(channel, r.event, now);
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
void CanAdapter::handle_famouso_protocol(const CanIdentifier& id, const canfd_frame& frame, std::size_t len, Nanos now) {
  const Table& table = *rx_table_;
  if (id.etag == kEtagCcpRsi) {
    if (table.tx_node) ccp_->reserve(*table.tx_node);
    const auto answer = ccp_->on_request(frame.can_id & CAN_EFF_MASK, now);
    if (answer) {
      std::lock_guard lock(io_mutex_);
      queue_answer(answer->can_id, answer->data);
    } else if (ccp_->exhausted()) {
      problem(kNoChannel, InboundProblem::decode_error);
      log_.log(LogLevel::warning, "segment " + segment_.name + ": CCP: every TxNode is taken, a node stays unconfigured");
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
  log_.log(LogLevel::notice, "segment " + segment_.name + ": FAMOUSO node " + std::to_string(id.tx_node) +
                                 " subscribes subject " + text + (bound ? "" : " (no channel bound for it)"));
}

void CanAdapter::deliver(const RxChannel& channel, std::span<const std::uint8_t> payload, Nanos now) {
  InboundEvent event;
  event.channel = channel.id;
  event.header.subject = channel.subject;
  event.payload = payload;
  event.received_at = now;
  if (sink_) sink_->on_event(event);
}

void CanAdapter::deliver_native(const can_native::RxChannel& channel, std::span<const std::uint8_t> data, bool fd_frame,
                                Nanos now) {
  const auto event = can_native::contents(channel, data, fd_frame);
  if (!event) {
    problem(channel.id, InboundProblem::decode_error);
    return;
  }
  deliver(RxChannel{channel.id, channel.subject, channel.payload, false}, *event, now);
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
  std::lock_guard lock(io_mutex_);
  if (!request_limit_.admit(request->requester, now)) {
    ++receive_errors_;
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
    log_.log(LogLevel::warning, "segment " + segment_.name + ": GET_ETAG from TxNode " +
                                    std::to_string(request.requester) + " over the rate limit, " +
                                    (kept ? "answered later" : known ? "already waiting" : "deferred queue full, dropped") +
                                    " (" + std::to_string(over) + " over the limit so far)");
  }
}

void CanAdapter::serve_deferred_requests(Nanos now) {
  std::lock_guard lock(io_mutex_);
  if (deferred_requests_.empty()) return;
  const Table& table = *rx_table_;
  std::erase_if(deferred_requests_, [&](const can_binding::GetEtagRequest& r) {
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
  if (famouso_ && !known && pending_requests_.size() < kMaxPendingRequests) pending_requests_.push_back(request);
}

void CanAdapter::queue_supply_etag(std::uint8_t requester, std::uint16_t etag, std::uint64_t subject, const Table& table) {
  if (!famouso_ && !table.tx_node) return;  // no channel bound yet: the gateway has no TxNode here
  const std::uint32_t id = famouso_ ? can_binding::supply_etag_new_bp_id() : can_binding::supply_etag_id(*table.tx_node);
  const auto frames = can_binding::supply_etag_data(requester, etag, subject);
  if (!answers_.room_for(frames.size())) {
    send_errors_ += frames.size();
    return;
  }
  for (const auto& data : frames) queue_answer(id, data);
}

void CanAdapter::queue_answer(std::uint32_t can_id, std::span<const std::uint8_t> data) {
  if (!answers_.room_for(1)) {
    ++send_errors_;
    return;
  }
  can_frame out{};
  out.can_id = can_id | CAN_EFF_FLAG;
  out.len = static_cast<std::uint8_t>(std::min<std::size_t>(data.size(), CAN_MAX_DLEN));
  std::memcpy(out.data, data.data(), out.len);
  answers_.push(out);
  wake();
}

// One answer per call, only when no real-time frame waits in the backlog.
void CanAdapter::drain_answers() {
  std::lock_guard lock(io_mutex_);
  if (sock_ < 0 || !backlog_.empty()) return;
  const Nanos now = steady_now();
  const can_frame* answer = answers_.due(now);
  if (!answer) return;
  const ssize_t n = ::write(sock_, answer, CAN_MTU);
  if (n == static_cast<ssize_t>(CAN_MTU)) {
    ++sent_;
    answers_.sent(now);
    return;
  }
  const int err = n < 0 ? errno : EIO;
  if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
    answers_.wait(now);  // the kernel's queue is full: try again one gap later
    return;
  }
  ++send_errors_;
  answers_.sent(now);  // dropped
}

void CanAdapter::handle_protocol_timeouts(Nanos now) {
  afp_.expire(now, [this](std::uint32_t source) { reassembly_losses(kNoChannel, source, false); });
  if (!ccp_) return;
  if (const auto reset = ccp_->expire(now)) {
    std::lock_guard lock(io_mutex_);
    queue_answer(reset->can_id, reset->data);
  }
}

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
  std::lock_guard lock(io_mutex_);
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
    std::unique_lock lock(io_mutex_);
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
                                std::unique_lock<std::mutex>& lock) {
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

}  // namespace

std::unique_ptr<SegmentAdapter> make_can_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log) {
  (void)self;  // CAN frames carry no envelope: the gateway is known by its TxNode
  return std::make_unique<CanAdapter>(segment, log);
}

}  // namespace cosmic

// The SocketCAN adapter's class, shared by its translation units (internal to the CAN adapter):
//   can_adapter.cpp   lifecycle, configure (the binding tables), health, statistics
//   can_socket.cpp    the sockets and the link, the receive thread's loop and reads, the census
//   can_receive.cpp   frames to events (each binding's format), FAMOUSO protocols, binding answers
//   can_send.cpp      events to frames (each binding's format), the submit, the backlog
//   can_frame_format  the wire formats of bindings: cosmic, famouso, native
// Threads: see cosmic/segment_adapter.hpp; the members say which thread owns them.
#pragma once

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
#include <memory>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "binding_guard.hpp"
#include "can_binding.hpp"
#include "cosmic/adapter_counters.hpp"
#include "cosmic/health_cell.hpp"
#include "cosmic/log_prefix.hpp"
#include "cosmic/arrival_clock.hpp"
#include "cosmic/binding_plan.hpp"
#include "cosmic/posix_call.hpp"
#include "cosmic/receive_thread.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/thread_policy.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"
#include "can_frame_format.hpp"
#include "famouso_ccp.hpp"
#include "frame_backlog.hpp"
#include "bus_census.hpp"
#include "native_frames.hpp"
#include "receive_buffer.hpp"
#include "secoc_freshness.hpp"
#include "cosmic/can_adapter.hpp"

namespace cosmic::can_detail {
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
constexpr std::size_t kReadBatch = 32;                        // frames per recvmmsg
constexpr std::size_t kWriteBatch = FrameBacklog::kMaxTaken;  // frames per sendmmsg
static_assert(kWriteBatch == kFramesPerSubmit, "a format's batch is one submit");
constexpr can_err_mask_t kErrorMask = CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
constexpr Nanos kDeferredRequestRetry = std::chrono::milliseconds(20);  // well below one token (100 ms)
constexpr std::size_t kMaxPendingRequests = 64;          // FAMOUSO: unanswered GET_ETAGs kept for a later bind
constexpr std::size_t kMaxAnnouncedSubscriptions = 256;  // FAMOUSO: subscriptions logged once each
constexpr canid_t kEtagFilterMask = 0x3FFF | CAN_EFF_FLAG;

// Binding answers leave one at a time, two frame times apart (an extended 8-byte frame is at
// most 160 bits with stuffing), so at most one is in the kernel's FIFO ahead of a real-time frame.
inline Nanos answer_gap(const CanSegmentProperties& can) {
  const double bits = 2 * 160.0;
  const double rate = static_cast<double>(std::max<std::uint64_t>(can.bitrate.bits_per_second, 10'000));
  return std::max(Nanos(200'000), Nanos(static_cast<std::int64_t>(bits * 1e9 / rate)));
}

// Etags the socket receives whatever is bound: the binding protocol, and on a FAMOUSO segment
// the configuration protocol and the SUBSCRIBE announcements.
inline std::vector<can_filter> protocol_filters(bool famouso) {
  std::vector<can_filter> f{can_filter{kEtagGetEtag | CAN_EFF_FLAG, kEtagFilterMask}};
  if (famouso) {
    f.push_back(can_filter{kEtagCcpRsi | CAN_EFF_FLAG, kEtagFilterMask});
    f.push_back(can_filter{kEtagFamousoSubscribe | CAN_EFF_FLAG, kEtagFilterMask});
  }
  return f;
}

// The adapter's CAN_RAW socket. Senders write without holding the I/O lock, each with a
// reference taken under it; the descriptor is closed when the last reference goes, so the receive
// thread may give the socket up (interface gone, reopened) while a write is in flight without the
// number being reused under that write.
class TxSocket {
 public:
  explicit TxSocket(int fd) : fd_(fd) {}
  ~TxSocket() { ::close(fd_); }
  TxSocket(const TxSocket&) = delete;
  TxSocket& operator=(const TxSocket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};
using TxSocketRef = std::shared_ptr<const TxSocket>;

class CanAdapter final : public SegmentAdapter {
 public:
  CanAdapter(const SegmentSpec& segment, Logger& log, CanSecocState secoc, std::shared_ptr<WireTap> tap)
      : segment_(segment),
        log_(log),
        prefix_(segment_log_prefix(SegmentType::can, segment.name)),
        capacity_(max_frame_payload(segment.can)),
        brs_(segment.can.fd && segment.can.data_bitrate > segment.can.bitrate),
        famouso_protocol_(segment.can.profile == CanProfile::famouso),
        cosmic_frames_(CanBus{capacity_, segment.can.fd, brs_},
                       CanReassemblyBounds{kMaxPartialEvents, kReassemblyTimeout}),
        famouso_frames_(CanReassemblyBounds{kMaxPartialEvents, kReassemblyTimeout}),
        native_frames_(CanBus{capacity_, segment.can.fd, brs_}),
        ccp_(segment.can.profile == CanProfile::famouso ? std::optional<famouso::CcpBroker>(std::in_place)
                                                        : std::nullopt),
        table_(std::make_shared<const Table>()),
        answers_(answer_gap(segment.can)),
        secoc_freshness_(secoc ? std::move(secoc)
                               : std::make_shared<SecocFreshness>(std::string(), prefix_, "fv:" + segment.name, log)),
        tap_(std::move(tap)) {}

  ~CanAdapter() override { stop(); }

  Status start(EventSink& sink) override;
  Status configure(std::span<const ChannelBinding> bindings) override;
  SendStatus send(const OutboundEvent& event) override;
  // Runs of events that are one frame each in their binding's format go out
  // in one submit (one sendmmsg); the others as send() sends them.
  void send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) override;
  bool batches_sends() const override { return true; }
  HealthReport health() const override;
  AdapterStatistics statistics() const override;
  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }  // broadcast bus
  void stop() override;

 private:
  struct Table {
    std::unordered_map<std::uint16_t, CanRxBinding> rx;        // etag -> channel bound as publisher
    std::unordered_map<ChannelId, CanTxBinding> tx;            // channels bound as subscriber, every format
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
  void size_receive_buffer(int s);  // receive_buffer.hpp
  void close_socket() COSMIC_EXCLUDES(io_mutex_);
  void read_frames();
  // sock_ as the receive thread sees it without io_mutex_: it is the only thread that changes sock_.
  int receive_socket() const COSMIC_NO_THREAD_SAFETY_ANALYSIS { return sock_; }
  // The census socket (bus_census.hpp): every frame on the bus, counted when nothing explains it.
  void open_census_socket(int ifindex);
  void read_census();
  bool explains(const Table& table, canid_t can_id) const;
  void handle_read_error(int err);
  void handle_datagram(canfd_frame& frame, msghdr& msg, std::size_t bytes);
  void handle_frame(const canfd_frame& frame, bool fd_frame, Nanos now);
  void handle_error_frame(const canfd_frame& frame);
  void handle_get_etag(const canfd_frame& frame, std::size_t len, Nanos now);
  void answer_request(const can_binding::GetEtagRequest& request, const Table& table) COSMIC_REQUIRES(io_mutex_);
  void defer_request(const can_binding::GetEtagRequest& request) COSMIC_REQUIRES(io_mutex_);
  void serve_deferred_requests(Nanos now) COSMIC_EXCLUDES(io_mutex_);
  void reassembly_losses(ChannelId channel, std::optional<std::uint32_t> displaced, bool lost);
  void handle_famouso_protocol(const CanIdentifier& id, const canfd_frame& frame, std::size_t len, Nanos now);
  void handle_protocol_timeouts(Nanos now);
  // A data frame of `binding`, through its format: the event it completes, or the loss it costs.
  void receive(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data, bool fd_frame,
               Nanos now);
  void deliver(const CanRxBinding& binding, std::span<const std::uint8_t> payload, Nanos now);
  void problem(ChannelId channel, InboundProblem what);
  void drain_backlog() COSMIC_EXCLUDES(io_mutex_);
  void refresh_rx_table() COSMIC_EXCLUDES(io_mutex_);  // the receive thread's snapshot of the bindings (rx_table_)
  // configure(): the tables of the bindings `plan` accepts, refusing in it what cannot be carried
  // (a refused channel is carried in no role).
  std::shared_ptr<Table> plan_table(BindingPlan& plan);
  std::shared_ptr<Table> build_table(BindingPlan& plan);
  // configure(): the format a binding's plan names (native identifier, or its profile's layout).
  CanFrameFormat& format_of(const CanHopPlan& plan);
  // configure(): one binding into `table`, or why it cannot be carried. The tables
  // point at the adapter's formats, through which the receive thread decodes.
  Result<void> bind_native(const ChannelBinding& b, Table& table);
  Result<void> bind_etag(const ChannelBinding& b, Table& table);
  // configure(): the binding's SecOC state (none without `secoc` on this segment), or why it cannot
  // be carried. `identifier`: the frames' (with CAN_EFF_FLAG when extended).
  struct SecocStreams {
    std::shared_ptr<SecocTx> tx;
    std::shared_ptr<SecocRx> rx;
  };
  Result<SecocStreams> bind_secoc(const ChannelBinding& b, canid_t identifier);
  // The secured PDU of an event of a SecOC hop in `out`, or the event as it is without SecOC; an
  // empty span when it cannot be protected (counted). Any lane.
  std::span<const std::uint8_t> secure(const CanTxBinding& binding, std::span<const std::uint8_t> payload,
                                       std::span<std::uint8_t> out);
  // A frame of a SecOC hop: its authentic data, or nothing (counted as unauthenticated or replayed).
  std::optional<std::span<const std::uint8_t>> authenticate(const CanRxBinding& binding, canid_t can_id,
                                                            std::span<const std::uint8_t> data, bool fd_frame);

  // --- health
  void set_link(Link link, std::string detail);
  void set_controller(Controller state);
  void update_health() COSMIC_REQUIRES(health_mutex_);

  // --- send side (can_send.cpp). No lock is held across a write: a lower class's sender held
  // up inside the kernel cannot hold up a higher class's sender, which waits at most for another
  // sender's few-instruction critical section (io_mutex_ inherits priority).
  // Frames of one event, in order, to the kernel or the backlog; takes io_mutex_ briefly.
  // Frames of several identifiers (a batch of events) go to the backlog whole while it holds
  // frames, which then leave in arbitration order.
  WriteResult submit(std::span<const canfd_frame> frames, bool fd) COSMIC_EXCLUDES(io_mutex_);
  // Whether a frame must wait behind the backlog: a queued or in-flight backlog frame would win
  // arbitration over it (or has its identifier), so writing it now would overtake that frame.
  bool behind_backlog(canid_t can_id) const COSMIC_REQUIRES(io_mutex_);
  WriteResult queue_frames(std::span<const canfd_frame> frames, bool fd) COSMIC_REQUIRES(io_mutex_);
  static SendStatus to_send_status(WriteResult result);
  void note_refusal(int err) COSMIC_REQUIRES(io_mutex_);  // EAGAIN/ENOBUFS: how the backlog waits
  // Counts; the first time, returns the line to log once io_mutex_ is given up (log_unlocked).
  std::string count_send_error(int err) COSMIC_REQUIRES(io_mutex_);
  void log_unlocked(const std::string& line) COSMIC_EXCLUDES(io_mutex_);  // a warning; nothing when empty
  // The event's binding when it can go out now as exactly one frame (send() takes the others).
  static const CanTxBinding* single_frame_binding(const Table& table, const OutboundEvent& event);
  void queue_answer(std::uint32_t can_id, std::span<const std::uint8_t> data) COSMIC_REQUIRES(io_mutex_);
  void queue_supply_etag(std::uint8_t requester, std::uint16_t etag, std::uint64_t subject, const Table& table)
      COSMIC_REQUIRES(io_mutex_);
  void drain_answers() COSMIC_EXCLUDES(io_mutex_);
  void wake();
  // The frames written, to the wire tap (if any). Any thread that writes.
  void tap_sent(std::span<const canfd_frame> frames, bool fd) const noexcept;
  // Returns the warning to log once io_mutex_ is given up (empty when nothing was queued).
  std::string drop_backlog(const char* why) COSMIC_REQUIRES(io_mutex_);

  const SegmentSpec segment_;
  Logger& log_;
  const std::string prefix_;      // "CAN segment NAME: " (cosmic/log_prefix.hpp)
  const std::uint32_t capacity_;  // data bytes of one frame on this bus
  const bool brs_;
  // The segment's binding protocol is FAMOUSO's: CCP, SUBSCRIBE announcements, etag-4 answers
  // (the frames of each binding are its format's).
  const bool famouso_protocol_;
  // The bindings' formats (can_frame_format.hpp): encoding is const and shared by the lanes;
  // their reassembly state is the receive thread's.
  CosmicFrames cosmic_frames_;
  FamousoFrames famouso_frames_;
  NativeFrames native_frames_;

  EventSink* sink_ = nullptr;
  ReceiveThread receiver_;  // runs run(); woken by senders that queued frames or answers
  std::atomic<bool> started_{false};
  int ctl_fd_ = -1;  // for interface ioctls (AF_UNIX: works without AF_CAN)

  // Receive-thread state.
  std::optional<famouso::CcpBroker> ccp_;                          // FAMOUSO segments only
  std::vector<std::pair<std::uint8_t, std::uint64_t>> announced_;  // FAMOUSO subscriptions seen (node, subject)
  std::shared_ptr<const Table> rx_table_;
  std::uint64_t rx_generation_ = ~0ull;
  int bound_ifindex_ = 0;
  Nanos next_link_check_{0};

  // Socket and send side. The receive thread opens and closes the socket (holding io_mutex_);
  // send() and the receive thread take a reference to it under io_mutex_ and write outside it.
  // A priority-inheriting mutex: the lanes of all three classes and the receive thread take it.
  mutable PiMutex io_mutex_;
  int sock_ COSMIC_GUARDED_BY(io_mutex_) = -1;          // the receive thread reads it unlocked: receive_socket()
  TxSocketRef tx_socket_ COSMIC_GUARDED_BY(io_mutex_);  // owns sock_'s descriptor
  int census_sock_ = -1;                                // only the receive thread opens, reads and closes it
  bool census_error_logged_ = false;
  bool receive_buffer_warned_ = false;  // receive thread
  std::shared_ptr<const Table> table_ COSMIC_GUARDED_BY(io_mutex_);
  std::atomic<std::uint64_t> generation_{0};
  FrameBacklog backlog_ COSMIC_GUARDED_BY(io_mutex_);
  // The arbitration key of the first backlog frame the receive thread is writing (taken out of
  // the backlog, not yet accepted by the kernel): it still counts as queued for behind_backlog().
  std::optional<std::uint32_t> draining_key_ COSMIC_GUARDED_BY(io_mutex_);
  ProtocolQueue answers_ COSMIC_GUARDED_BY(io_mutex_);  // binding and CCP answers: after the backlog, paced
  BindingRateLimit request_limit_ COSMIC_GUARDED_BY(io_mutex_);
  // FAMOUSO: unknown subjects, answered on bind
  std::vector<can_binding::GetEtagRequest> pending_requests_ COSMIC_GUARDED_BY(io_mutex_);
  // Requests over the rate limit, answered when the node's budget allows: a client that asks
  // once (FAMOUSO's) must not lose its binding to a burst at start-up. One entry per (node,
  // subject), bounded, so a flood costs a counter and at most one later answer.
  std::deque<can_binding::GetEtagRequest> deferred_requests_ COSMIC_GUARDED_BY(io_mutex_);
  std::atomic<std::uint64_t> refused_requests_{0};  // over the rate limit (deferred or dropped)
  std::unordered_map<std::uint16_t, std::uint8_t> tx_sequence_ COSMIC_GUARDED_BY(io_mutex_);
  bool wait_pollout_ COSMIC_GUARDED_BY(io_mutex_) = false;      // backlog waits for POLLOUT (EAGAIN)
  std::optional<Nanos> retry_at_ COSMIC_GUARDED_BY(io_mutex_);  // backlog waits for the qdisc (ENOBUFS)
  bool send_error_logged_ COSMIC_GUARDED_BY(io_mutex_) = false;
  std::atomic<bool> link_up_{false};

  // Health.
  mutable Mutex health_mutex_;
  Link link_ COSMIC_GUARDED_BY(health_mutex_) = Link::unknown;
  std::string link_detail_ COSMIC_GUARDED_BY(health_mutex_) = "not started";
  Controller controller_ COSMIC_GUARDED_BY(health_mutex_) = Controller::ok;
  HealthReport shown_ COSMIC_GUARDED_BY(health_mutex_){SegmentHealth::down, "not started"};  // last logged
  HealthCell health_;  // what health() answers, any thread

  // Statistics.
  // received, sent and the errors (the kit's counters); overflow_drops is the sum below.
  AdapterCounters counters_;
  std::atomic<std::uint64_t> overflow_closed_{0};  // SO_RXQ_OVFL of sockets already closed
  std::atomic<std::uint64_t> overflow_socket_{0};  // SO_RXQ_OVFL of the open socket
  std::atomic<std::uint64_t> overflow_controller_{0};
  std::atomic<std::uint64_t> backlog_size_{0};
  can_census::BusCensus census_;

  // SecOC (secoc_freshness.hpp): the counters of the hops' senders and receivers, persisted.
  const std::shared_ptr<SecocFreshness> secoc_freshness_;  // never null; attached while started
  std::atomic<bool> secoc_bound_{false};                   // a SecOC hop was bound: statistics show its counters
  std::atomic<std::uint64_t> secoc_unauthenticated_{0};
  std::atomic<std::uint64_t> secoc_replayed_{0};

  const std::shared_ptr<WireTap> tap_;  // null: none (CanAdapterOptions::tap)
};

}  // namespace cosmic::can_detail

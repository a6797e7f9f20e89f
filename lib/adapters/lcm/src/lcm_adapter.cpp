// LCM segment adapter. See cosmic/lcm_adapter.hpp for the mapping.
//
// The transport is the gateway's own (lcm_sockets.hpp over the udpm wire format of
// cosmic/lcm_udpm.hpp), not liblcm: one receive socket read in batches (recvmmsg) by the
// segment's receive thread, which parses, reassembles and hands events on itself, and one
// connected transmit socket per channel class.
//
// Threads and locks:
//   control_mutex_  serialises start/configure/stop (control thread) and guards the receive
//                   socket and thread.
//   table_mutex_    shared_mutex over the channel table and the sink. send() (lane threads) takes
//                   it shared for one event, the receive thread for one batch of datagrams;
//                   configure() and stop() take it exclusively only to swap the table or the sink,
//                   never around I/O.
//   senders_[class] one transmit socket, its LCM sequence number and the envelope header per
//                   channel class, each under its own mutex held across sendmsg: an NRT send
//                   stalled in the kernel never holds what an HRT send needs (issue 20, item 2).
// Our own datagrams loop back to the receive socket (multicast loopback stays on so programs on
// this host hear the gateway). A socket filter drops them in the kernel by their source, the
// address and port of one of our connected transmit sockets; where it cannot be attached the
// receive thread tells them by that source itself and reports them as own_echo.
// The EventSink is called with table_mutex_ held shared: it must hand the event on (the router
// queues it) and not call back into this adapter.
#include "cosmic/lcm_adapter.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <exception>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "cosmic/adapter_counters.hpp"
#include "cosmic/arrival_clock.hpp"
#include "cosmic/health_cell.hpp"
#include "cosmic/lcm_reassembly.hpp"
#include "cosmic/lcm_udpm.hpp"
#include "cosmic/lcm_url.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/thread_policy.hpp"
#include "cosmic/transport_limits.hpp"
#include "lcm_sockets.hpp"

namespace cosmic {
namespace {

using lcm_detail::Endpoint;

constexpr int kRetryAfterFailureMs = 100;  // pause before reading again after a failing read
constexpr std::size_t kReceiveBatch = 32;  // datagrams per recvmmsg
// The receive socket's buffer unless the URL names one (recv_buf_size): about 5,000 small
// datagrams or 60 of 64 KiB, what liblcm's queues held before (4,096 messages).
constexpr std::size_t kDefaultReceiveBuffer = 4u << 20;

struct StringHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view s) const noexcept { return std::hash<std::string_view>{}(s); }
};

// One channel bound on this segment. rx: the gateway receives it here (HopRole::publisher);
// tx: the gateway sends it here (HopRole::subscriber). Both may be set.
struct Channel {
  ChannelId id = kNoChannel;
  std::string name;
  std::uint64_t subject = 0;
  LcmEncoding encoding = LcmEncoding::envelope;
  ChannelClass cls = ChannelClass::nrt;  // which transmit socket sends it
  bool rx = false;
  bool tx = false;
};

class LcmAdapter final : public SegmentAdapter {
 public:
  // An envelope's origin is not compared with ours here: our own datagrams are known by their
  // source, and the router's ingress check counts any other envelope carrying our origin.
  LcmAdapter(const SegmentSpec& segment, Logger& log)
      : segment_(segment), log_(log), reassembler_(segment.max_message_size) {}

  ~LcmAdapter() override { stop(); }

  LcmAdapter(const LcmAdapter&) = delete;
  LcmAdapter& operator=(const LcmAdapter&) = delete;

  Status start(EventSink& sink) override {
    LockGuard control(control_mutex_);
    if (started_) return Status::failure("LCM segment " + segment_.name + " already started");
    const auto parsed = parse_lcm_url(segment_.lcm.url);
    if (const auto* why = std::get_if<std::string>(&parsed)) return fail_start("bad LCM URL " + segment_.lcm.url + ": " + *why);
    const LcmUrl& url = std::get<LcmUrl>(parsed);
    if (url.memq) {
      // memq:// is private to one LCM instance: nothing reaches this segment and what it sends
      // reaches no one else. It stays up, with no socket and no thread.
      memq_.store(true, std::memory_order_relaxed);
      attach_sink(&sink);
      started_ = true;
      set_health(SegmentHealth::up, "");
      return Status{};
    }
    if (const auto why = open_senders(url)) return fail_start(*why);
    lcm_detail::OpenedSocket rx = lcm_detail::open_receive_socket(url, kDefaultReceiveBuffer);
    if (rx.fd < 0) {
      close_senders();
      return fail_start("receive socket on " + segment_.lcm.url + ": " + rx.error);
    }
    if (const auto why = lcm_detail::drop_own_datagrams(rx.fd, own_sources_))
      rx.warnings.push_back("own datagrams are read back and dropped here (" + *why + ")");
    for (const auto& warning : rx.warnings) log_.log(LogLevel::warning, "LCM segment " + segment_.name + ": " + warning);
    stop_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (stop_fd_ < 0) {
      const std::string why = std::string("eventfd for the receive loop: ") + std::strerror(errno);
      ::close(rx.fd);
      close_senders();
      return fail_start(why);
    }
    rx_fd_ = rx.fd;
    attach_sink(&sink);
    running_.store(true, std::memory_order_release);
    try {
      ThreadPolicy policy = sink.receive_thread_policy();
      policy.name = "rx:" + segment_.name;
      thread_ = std::thread([this, fd = rx_fd_, stop_fd = stop_fd_, policy] { receive_loop(fd, stop_fd, policy); });
    } catch (const std::exception& e) {
      running_.store(false);
      attach_sink(nullptr);
      ::close(std::exchange(stop_fd_, -1));
      ::close(std::exchange(rx_fd_, -1));
      close_senders();
      return fail_start(std::string("cannot start the LCM receive thread: ") + e.what());
    }
    started_ = true;
    set_health(SegmentHealth::up, "");
    log_.log(LogLevel::info, "LCM segment " + segment_.name + " up on " + segment_.lcm.url);
    return Status{};
  }

  Status configure(std::span<const ChannelBinding> bindings) override {
    LockGuard control(control_mutex_);
    // Every problem here concerns one channel (Status::refused); LCM has no failure of the whole
    // segment once started.
    Status status;
    auto refuse = [&status](ChannelId id, const std::string& name, const std::string& why) {
      status.ok = false;
      status.error += (status.error.empty() ? "" : "; ") + ("channel " + name + ": " + why);
      status.refused.push_back(ChannelRefusal{id, why});
    };
    std::unordered_map<ChannelId, Channel> wanted;
    std::unordered_map<std::string, ChannelId> names;
    std::set<ChannelId> refused_ids;
    for (const ChannelBinding& b : bindings) {
      // A native binding names the LCM channel and carries the contents raw.
      const NativeBinding* native = b.spec.native_on(segment_.name);
      const std::string& name = native && native->lcm_channel ? *native->lcm_channel : b.spec.name;
      if (const auto problem = binding_problem(b, name, names)) {
        refuse(b.id, name.empty() ? b.spec.name : name, *problem);
        refused_ids.insert(b.id);
        continue;
      }
      names.emplace(name, b.id);
      Channel& c = wanted[b.id];
      c.id = b.id;
      c.name = name;
      c.subject = b.spec.subject;
      c.encoding = native && native->lcm_channel ? LcmEncoding::raw : b.spec.lcm_encoding;
      c.cls = b.spec.cls;
      if (b.role == HopRole::publisher) c.rx = true;
      if (b.role == HopRole::subscriber) c.tx = true;
    }
    // A channel refused in one role is not carried in the other either.
    for (const ChannelId id : refused_ids) wanted.erase(id);
    // Swap the table (brief exclusive lock; channels kept keep flowing through it). Every
    // datagram reaches the receive socket anyway: reception is a lookup by name, no subscription.
    std::unordered_map<std::string, Channel*, StringHash, std::equal_to<>> by_name;
    LockGuard table(table_mutex_);
    channels_ = std::move(wanted);
    for (auto& [id, channel] : channels_) by_name.emplace(channel.name, &channel);
    by_name_ = std::move(by_name);
    if (!status.ok) log_.log(LogLevel::warning, "LCM segment " + segment_.name + ": " + status.error);
    return status;
  }

  SendStatus send(const OutboundEvent& event) override {
    SharedLock table(table_mutex_);
    const Channel* channel = transmitting(event.channel);
    if (channel == nullptr) return unbound();
    ClassSender& sender = senders_.at(static_cast<std::size_t>(channel->cls));
    LockGuard transmit(sender.mutex);
    return send_one(sender, *channel, event);
  }

  // An egress lane's batch: each run of events of one class that fit one datagram goes out in
  // one sendmmsg, in order; a message that needs fragments goes alone.
  void send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) override {
    const std::size_t n = std::min(events.size(), results.size());
    SharedLock table(table_mutex_);
    std::size_t i = 0;
    while (i < n) {
      const Channel* first = transmitting(events[i].channel);
      if (first == nullptr) {
        results[i++] = unbound();
        continue;
      }
      ClassSender& sender = senders_.at(static_cast<std::size_t>(first->cls));
      LockGuard transmit(sender.mutex);
      std::array<std::size_t, lcm_detail::SendBatch::kCapacity> staged{};  // indices into events
      std::size_t count = 0;
      for (; i < n; ++i) {
        const Channel* channel = transmitting(events[i].channel);
        if (channel == nullptr) {
          results[i] = unbound();
          continue;
        }
        if (channel->cls != first->cls || !stage(sender, *channel, events[i])) break;
        staged[count++] = i;
      }
      if (count == 0) {  // the message at i needs fragments, or there is no socket (memq, stopped)
        results[i] = send_one(sender, *first, events[i]);
        ++i;
        continue;
      }
      const auto why = sender.batch.send(sender.fd);
      for (std::size_t k = 0; k < count; ++k) {
        results[staged[k]] = sender.batch.failed(k)
                                 ? send_failed(*transmitting(events[staged[k]].channel), why ? why->c_str() : "sendmmsg")
                                 : sent();
      }
    }
  }

  bool batches_sends() const override { return true; }

  HealthReport health() const override { return health_.get(); }

  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }  // multicast: unknowable

  AdapterStatistics statistics() const override { return counters_.snapshot(); }

  void stop() override {
    LockGuard control(control_mutex_);
    if (!started_) return;
    started_ = false;
    if (thread_.joinable()) {
      running_.store(false, std::memory_order_release);
      const std::uint64_t one = 1;
      [[maybe_unused]] const ssize_t n = ::write(stop_fd_, &one, sizeof one);
      thread_.join();
      ::close(std::exchange(stop_fd_, -1));
      ::close(std::exchange(rx_fd_, -1));
    }
    attach_sink(nullptr);  // waits for sends in flight
    close_senders();
    memq_.store(false, std::memory_order_relaxed);
    set_health(SegmentHealth::down, "stopped");
    log_.log(LogLevel::info, "LCM segment " + segment_.name + " stopped");
  }

 private:
  // What one channel class sends with (see the top of this file).
  struct ClassSender {
    Mutex mutex;
    int fd COSMIC_GUARDED_BY(mutex) = -1;  // connected to the group; closed by close_senders()
    std::uint32_t sequence COSMIC_GUARDED_BY(mutex) = 0;  // LCM's per-sender message number
    // Envelope headers of the messages in flight, one per batch slot.
    std::array<std::array<std::uint8_t, kLcmEnvelopeHeaderSize>, lcm_detail::SendBatch::kCapacity>
        envelope_headers COSMIC_GUARDED_BY(mutex){};
    lcm_detail::SendBatch batch COSMIC_GUARDED_BY(mutex);
  };

  const Channel* transmitting(ChannelId id) const COSMIC_REQUIRES_SHARED(table_mutex_) {
    const auto it = channels_.find(id);
    if (sink_ == nullptr || it == channels_.end() || !it->second.tx) return nullptr;
    return &it->second;
  }

  SendStatus unbound() {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return SendStatus::failed;
  }

  // The parts of `event` as LCM carries it on `channel`: its payload, after the envelope's
  // header (written to `header`) on an envelope channel. nullopt when it is too large for one.
  static std::optional<std::size_t> message_parts(const Channel& channel, const OutboundEvent& event,
                                                  std::array<std::uint8_t, kLcmEnvelopeHeaderSize>& header,
                                                  std::array<std::span<const std::uint8_t>, 2>& parts) {
    std::size_t count = 0;
    if (channel.encoding == LcmEncoding::envelope) {
      if (event.payload.size() > static_cast<std::size_t>(INT32_MAX) - kLcmEnvelopeHeaderSize) return std::nullopt;
      // The header goes out as given, as on DDS: the router stamps what this gateway originates
      // with its id, a component (libcosmic-client) stamps its own.
      header = encode_lcm_envelope_header(event.header, static_cast<std::uint32_t>(event.payload.size()));
      parts[count++] = header;
    }
    parts[count++] = event.payload;
    return count;
  }

  SendStatus send_one(ClassSender& sender, const Channel& channel, const OutboundEvent& event)
      COSMIC_REQUIRES(sender.mutex) {
    if (memq_.load(std::memory_order_relaxed)) return sent();
    if (sender.fd < 0) return send_failed(channel, "not started");
    std::array<std::span<const std::uint8_t>, 2> parts{};
    const auto count = message_parts(channel, event, sender.envelope_headers[0], parts);
    if (!count) return send_failed(channel, "payload too large");
    const auto why = lcm_detail::send_lcm_message(sender.fd, sender.sequence++, channel.name, std::span(parts.data(), *count));
    return why ? send_failed(channel, why->c_str()) : sent();
  }

  // Adds `event` to the sender's batch; false when it does not fit one datagram or the batch.
  bool stage(ClassSender& sender, const Channel& channel, const OutboundEvent& event) COSMIC_REQUIRES(sender.mutex) {
    const std::size_t slot = sender.batch.size();
    if (slot >= lcm_detail::SendBatch::kCapacity || sender.fd < 0) return false;
    std::array<std::span<const std::uint8_t>, 2> parts{};
    const auto count = message_parts(channel, event, sender.envelope_headers[slot], parts);
    if (!count) return false;
    if (!sender.batch.add(sender.sequence, channel.name, std::span(parts.data(), *count))) return false;
    ++sender.sequence;
    return true;
  }

  Status fail_start(const std::string& why) {
    set_health(SegmentHealth::down, why);
    log_.log(LogLevel::error, "LCM segment " + segment_.name + ": " + why);
    return Status::failure(why);
  }

  void attach_sink(EventSink* sink) {
    LockGuard table(table_mutex_);
    sink_ = sink;
  }

  // Why binding `b` under LCM channel `name` cannot be carried, given the names taken so far.
  std::optional<std::string> binding_problem(const ChannelBinding& b, const std::string& name,
                                             const std::unordered_map<std::string, ChannelId>& names) const {
    if (b.id == kNoChannel || name.empty()) return std::string("no channel id or name");
    if (auto problem = transport_name_problem(SegmentType::lcm, name)) return problem;
    const auto taken = names.find(name);
    if (taken != names.end() && taken->second != b.id) {
      return "LCM channel '" + name + "' is already bound by channel id " + std::to_string(taken->second);
    }
    const auto same_id = std::find_if(names.begin(), names.end(), [&](const auto& n) { return n.second == b.id; });
    if (same_id != names.end() && same_id->first != name) {
      return "channel id " + std::to_string(b.id) + " is already bound as LCM channel '" + same_id->first + "'";
    }
    return std::nullopt;
  }

  // One connected transmit socket per class (start(), control thread), their sources noted for
  // the receive thread; the reason when one fails.
  std::optional<std::string> open_senders(const LcmUrl& url) COSMIC_REQUIRES(control_mutex_) {
    for (std::size_t i = 0; i < senders_.size(); ++i) {
      lcm_detail::OpenedSocket tx = lcm_detail::open_send_socket(url);
      if (tx.fd < 0) {
        close_senders();
        return "transmit socket on " + segment_.lcm.url + ": " + tx.error;
      }
      LockGuard lock(senders_[i].mutex);
      senders_[i].fd = tx.fd;
      own_sources_[i] = tx.local;
    }
    return std::nullopt;
  }

  void close_senders() {
    for (ClassSender& sender : senders_) {
      LockGuard lock(sender.mutex);  // waits for a send in flight
      if (sender.fd >= 0) ::close(std::exchange(sender.fd, -1));
    }
  }

  // The segment's receive thread: waits for datagrams or stop(), then reads all that are queued
  // in batches and hands each batch's events on under one shared table lock.
  void receive_loop(int fd, int stop_fd, const ThreadPolicy& policy) {
    for (const auto& problem : apply_thread_policy(policy))
      log_.log(LogLevel::warning, "LCM segment " + segment_.name + ": receive thread: " + problem);
    lcm_detail::ReceiveBatch batch(kReceiveBatch);
    bool failing = false;
    while (running_.load(std::memory_order_acquire)) {
      pollfd fds[2] = {{fd, POLLIN, 0}, {stop_fd, POLLIN, 0}};
      // A failing read is retried after a pause rather than in a spin; stop_fd still ends it.
      const int ready = ::poll(fds, 2, failing ? kRetryAfterFailureMs : -1);
      if (ready < 0 && errno != EINTR) {
        note_receive_failure(failing, "poll: " + std::string(std::strerror(errno)));
        continue;
      }
      if (fds[1].revents != 0) break;
      if (ready <= 0 || (fds[0].revents & POLLIN) == 0) continue;
      for (;;) {
        const int n = batch.receive(fd);
        if (n < 0) {
          note_receive_failure(failing, "recvmmsg: " + std::string(std::strerror(errno)));
          break;
        }
        if (n == 0) break;
        handle_batch(batch, static_cast<std::size_t>(n));
        if (failing) {
          failing = false;
          set_health(SegmentHealth::up, "");
          log_.log(LogLevel::notice, "LCM segment " + segment_.name + " receiving again");
        }
        if (static_cast<std::size_t>(n) < batch.slots()) break;  // the queue is empty now
      }
    }
  }

  void note_receive_failure(bool& failing, const std::string& what) {
    if (failing) return;
    failing = true;
    set_health(SegmentHealth::degraded, what + " on " + segment_.lcm.url);
    log_.log(LogLevel::error, "LCM segment " + segment_.name + ": " + what);
  }

  bool own_source(Endpoint from) const {
    return std::find(own_sources_.begin(), own_sources_.end(), from) != own_sources_.end();
  }

  // Receive thread only.
  void handle_batch(const lcm_detail::ReceiveBatch& batch, std::size_t count) {
    if (const auto drops = batch.kernel_drops()) counters_.overflow_drops.store(*drops, std::memory_order_relaxed);
    // One reading of both clocks for the batch: arrival times are converted with it.
    const std::int64_t steady_now = std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()).count();
    const std::int64_t realtime_now =
        std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
    SharedLock table(table_mutex_);
    if (sink_ == nullptr) return;
    for (std::size_t i = 0; i < count; ++i) {
      const auto parsed = batch.truncated(i) ? std::nullopt : parse_lcm_datagram(batch.datagram(i));
      if (!parsed) {
        counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);  // not LCM's, or damaged
        continue;
      }
      std::int64_t arrival = batch.arrival_realtime_ns(i);
      if (arrival == 0) arrival = realtime_now;
      const Nanos received_at = steady_arrival(arrival, Nanos(steady_now), realtime_now);
      const Endpoint from = batch.sender(i);
      if (own_source(from)) {
        // Ours, looped back: one report per message (at its only or first datagram).
        if (!parsed->channel.empty()) report_echo(parsed->channel);
        continue;
      }
      if (!parsed->fragment) {
        deliver(parsed->channel, parsed->data, received_at, arrival);
        continue;
      }
      // Only a channel bound here is worth reassembling; fragments after the first carry no name.
      if (!parsed->channel.empty() && !receives(parsed->channel)) continue;
      const auto outcome = reassembler_.add(from.key(), *parsed);
      if (outcome == LcmReassembler::Outcome::complete)
        deliver(reassembler_.channel(), reassembler_.payload(), received_at, arrival);
    }
  }

  bool receives(std::string_view name) const COSMIC_REQUIRES_SHARED(table_mutex_) {
    const auto it = by_name_.find(name);
    return it != by_name_.end() && it->second->rx;
  }

  void report_echo(std::string_view name) COSMIC_REQUIRES_SHARED(table_mutex_) {
    const auto it = by_name_.find(name);
    if (it != by_name_.end() && it->second->rx) sink_->on_problem(it->second->id, InboundProblem::own_echo);
  }

  // One whole message of LCM channel `name`; table_mutex_ held shared by the caller.
  void deliver(std::string_view name, std::span<const std::uint8_t> bytes, Nanos received_at,
               std::int64_t arrival_realtime_ns) COSMIC_REQUIRES_SHARED(table_mutex_) {
    const auto it = by_name_.find(name);
    if (it == by_name_.end() || !it->second->rx) return;  // not bound for reception here
    const Channel& channel = *it->second;
    counters_.received.fetch_add(1, std::memory_order_relaxed);
    InboundEvent event;
    event.channel = channel.id;
    event.received_at = received_at;
    if (channel.encoding == LcmEncoding::raw) {
      event.header.subject = channel.subject;
      event.header.created_ns = arrival_realtime_ns;  // wall clock, informational
      event.payload = bytes;
      event.guard_loops_by_fingerprint = true;
      sink_->on_event(event);
      return;
    }
    // Decoded in place (cosmic/lcm_wire.hpp): the payload stays in the receive buffer, no copy.
    const auto decoded = decode_lcm_envelope(bytes, segment_.max_message_size);
    if (!decoded) {
      counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
      sink_->on_problem(channel.id, InboundProblem::decode_error);
      return;
    }
    // An envelope with our origin that is not our own datagram (a loop through another gateway,
    // or a spoof) goes on to the router, which counts it (ingress check: own origin).
    event.header = decoded->header;
    event.payload = decoded->payload;
    sink_->on_event(event);
  }

  SendStatus sent() {
    counters_.sent.fetch_add(1, std::memory_order_relaxed);
    send_failing_.store(false, std::memory_order_relaxed);
    return SendStatus::sent;
  }

  SendStatus send_failed(const Channel& channel, const char* why) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    // Log the first failure of a run of failures, not every event.
    if (!send_failing_.exchange(true, std::memory_order_relaxed))
      log_.log(LogLevel::warning, "LCM segment " + segment_.name + ": send on channel " + channel.name + ": " + why);
    return SendStatus::failed;
  }

  void set_health(SegmentHealth state, std::string detail) { health_.set(state, std::move(detail)); }

  const SegmentSpec segment_;
  Logger& log_;

  Mutex control_mutex_;
  bool started_ COSMIC_GUARDED_BY(control_mutex_) = false;
  std::thread thread_ COSMIC_GUARDED_BY(control_mutex_);
  int rx_fd_ COSMIC_GUARDED_BY(control_mutex_) = -1;
  int stop_fd_ COSMIC_GUARDED_BY(control_mutex_) = -1;  // eventfd: stop() wakes the receive loop
  std::atomic<bool> running_{false};
  // Written by start() before the receive thread exists, read by that thread only.
  std::array<Endpoint, 3> own_sources_{};
  // memq://: set by start() before the sink is attached, cleared by stop() after it is detached.
  std::atomic<bool> memq_{false};

  mutable SharedMutex table_mutex_;
  EventSink* sink_ COSMIC_GUARDED_BY(table_mutex_) = nullptr;
  std::unordered_map<ChannelId, Channel> channels_ COSMIC_GUARDED_BY(table_mutex_);
  std::unordered_map<std::string, Channel*, StringHash, std::equal_to<>> by_name_ COSMIC_GUARDED_BY(table_mutex_);

  std::array<ClassSender, 3> senders_;  // indexed by ChannelClass
  LcmReassembler reassembler_;          // receive thread only

  AdapterCounters counters_;
  HealthCell health_;
  std::atomic<bool> send_failing_{false};
};

}  // namespace

std::unique_ptr<SegmentAdapter> make_lcm_adapter(const SegmentSpec& segment, const GatewayIdentity& /*self*/,
                                                 Logger& log) {
  return std::make_unique<LcmAdapter>(segment, log);
}

}  // namespace cosmic

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
//   table_          the channel table and the sink as a snapshot (cosmic/snapshot_table.hpp).
//                   send() (lane threads) reads it for one event or batch, the receive thread for
//                   one batch of datagrams: a pointer copy under a priority-inheriting mutex, then
//                   no lock while they send or hand events on. configure(), start() and stop()
//                   (the control thread, under control_mutex_) build the next table outside any
//                   lock, swap it in and wait until the last reading of the old one has ended.
//   transmit_       the per-class transmit sockets, each under its own mutex (lcm_transmit.hpp).
//   own_count_mutex_ the own_datagrams_dropped bookkeeping: statistics() from any thread, start()
//                   and stop() write it; never taken on the forwarding path.
// Our own datagrams loop back to the receive socket (multicast loopback stays on so programs on
// this host hear the gateway). A socket filter picks them out in the kernel by their source, the
// address and port of one of our connected transmit sockets, and drops them (own_datagrams: drop,
// the default) or cuts them down to nothing, which the receive thread then skips by that source.
// The receive socket is a member of the group only while a channel is received here (join_group,
// leave_group), so a segment that only sends gets none of them back.
// With `auth` (cosmic/lcm_auth.hpp) the transmitter signs each message, the receive thread checks
// each one received before its format reads it (lcm_auth_refusals.hpp: what it refuses).
// The EventSink is called while the receive thread reads the table: it must hand the event on
// (the router queues it) and not call back into this adapter's configure() or stop(), which
// would wait for that reading to end.
#include "cosmic/lcm_adapter.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
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
#include "cosmic/binding_plan.hpp"
#include "cosmic/health_cell.hpp"
#include "cosmic/lcm_auth.hpp"
#include "cosmic/lcm_reassembly.hpp"
#include "cosmic/lcm_udpm.hpp"
#include "cosmic/lcm_url.hpp"
#include "cosmic/receive_thread.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/log_prefix.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/snapshot_table.hpp"
#include "cosmic/result.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/thread_policy.hpp"
#include "cosmic/transport_limits.hpp"
#include "lcm_auth_refusals.hpp"
#include "lcm_channel.hpp"
#include "lcm_sockets.hpp"
#include "lcm_transmit.hpp"

namespace cosmic {
namespace {

using lcm_detail::Endpoint;

constexpr int kRetryAfterFailureMs = 100;  // pause before reading again after a failing read
constexpr std::size_t kReceiveBatch = 32;  // datagrams per recvmmsg
// How long start() waits for its own LCM_SELF_TEST message to come back (liblcm's check).
constexpr std::chrono::milliseconds kSelfTestTimeout{2000};
// The receive socket's buffer unless the URL names one (recv_buf_size): about 5,000 small
// datagrams or 60 of 64 KiB, what liblcm's queues held before (4,096 messages).
constexpr std::size_t kDefaultReceiveBuffer = 4u << 20;

struct StringHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view s) const noexcept { return std::hash<std::string_view>{}(s); }
};

using lcm_detail::Channel;
using lcm_detail::LcmArrival;

// The channels bound on the segment, built by configure() and never changed after.
struct ChannelIndex {
  std::unordered_map<ChannelId, Channel> by_id;
  std::unordered_map<std::string, const Channel*, StringHash, std::equal_to<>> by_name;  // into by_id
};
// What send() and the receive thread read: the channels, and the sink (null: not started).
struct ChannelTable {
  std::shared_ptr<const ChannelIndex> channels = std::make_shared<const ChannelIndex>();
  EventSink* sink = nullptr;
};
using lcm_detail::make_lcm_message_format;

class LcmAdapter final : public SegmentAdapter {
 public:
  // An envelope's origin is not compared with ours here: our own datagrams are known by their
  // source, and the router's ingress check counts any other envelope carrying our origin.
  LcmAdapter(const SegmentSpec& segment, Logger& log)
      : segment_(segment),
        log_(log),
        prefix_(segment_log_prefix(SegmentType::lcm, segment.name)),
        transmit_(segment.name, segment_.lcm.auth ? &*segment_.lcm.auth : nullptr, log, counters_, health_,
                  receive_failing_),
        // An envelope's payload may be max_message_size bytes: the message is its header longer,
        // and its authentication trailer.
        reassembler_(segment.max_message_size + kLcmEnvelopeHeaderSize + (segment.lcm.auth ? kLcmAuthTrailerSize : 0)),
        refusals_(prefix_, segment.lcm.auth ? segment.lcm.auth->window : Nanos(0), log) {}

  ~LcmAdapter() override { stop(); }

  LcmAdapter(const LcmAdapter&) = delete;
  LcmAdapter& operator=(const LcmAdapter&) = delete;

  Status start(EventSink& sink) override {
    LockGuard control(control_mutex_);
    if (started_) return Status::failure(prefix_ + "already started");
    const Result<LcmUrl> parsed = parse_lcm_url(segment_.lcm.url);
    if (!parsed) return fail_start("bad LCM URL " + segment_.lcm.url + ": " + parsed.error().text);
    const LcmUrl& url = parsed.value();
    if (url.memq) {
      // memq:// is private to one LCM instance: nothing reaches this segment and what it sends
      // reaches no one else. It stays up, with no socket and no thread.
      memq_.store(true, std::memory_order_relaxed);
      attach_sink(&sink);
      started_ = true;
      set_health(SegmentHealth::up, "");
      return Status{};
    }
    if (segment_.lcm.auth) {
      Result<LcmAuthVerifier> verifier = lcm_detail::make_verifier(*segment_.lcm.auth);
      if (!verifier) return fail_start("cannot check authentication: " + verifier.error().text);
      verifier_.emplace(std::move(verifier).value());  // before the receive thread that uses it starts
    }
    if (Result<void> opened = transmit_.open(url); !opened) return fail_start(std::move(opened).error().text);
    lcm_detail::OpenedSocket rx = lcm_detail::open_receive_socket(url, kDefaultReceiveBuffer);
    if (rx.fd < 0) {
      transmit_.close();
      return fail_start("receive socket on " + segment_.lcm.url + ": " + rx.error);
    }
    // Before the filter: the probe comes from a socket of its own, and this is where liblcm checked.
    if (Result<void> came_back = lcm_detail::self_test(url, rx.fd, kSelfTestTimeout); !came_back) {
      transmit_.close();
      ::close(rx.fd);
      return fail_start(std::move(came_back).error().text);
    }
    bool own_dropped = segment_.lcm.own_datagrams == LcmOwnDatagrams::drop;
    if (const Result<void> followed = transmit_.follow_with_filter(rx.fd, segment_.lcm.own_datagrams); !followed) {
      rx.warnings.push_back("own datagrams are read back in full and skipped here (" + followed.error().text + ")");
      own_dropped = false;
    }
    for (const auto& warning : rx.warnings) log_.log(LogLevel::warning, prefix_ + warning);
    rx_fd_ = rx.fd;
    rx_url_ = url;
    member_ = true;  // open_receive_socket() joined the group
    may_leave_ = rx.sees_own_groups_only;
    if (!receives_any(table_.current_for_publisher())) leave_group();
    receive_failing_.store(false, std::memory_order_relaxed);
    overflow_seen_ = 0;  // a new socket and transmitter count from 0; its thread starts below
    overflow_total_ = 0;
    overflow_reported_ = 0;
    attach_sink(&sink);
    ThreadPolicy policy = sink.receive_thread_policy();
    policy.name = "rx:" + segment_.name;
    auto running = receiver_.start(policy, log_, prefix_, [this, fd = rx_fd_] { receive_loop(fd); });
    if (!running) {
      attach_sink(nullptr);
      transmit_.close();
      ::close(std::exchange(rx_fd_, -1));
      return fail_start(running.error().text);
    }
    count_own_drops(own_dropped);
    started_ = true;
    set_health(SegmentHealth::up, "");
    log_.log(LogLevel::info, prefix_ + "up on " + segment_.lcm.url);
    return Status{};
  }

  Status configure(std::span<const ChannelBinding> bindings) override {
    LockGuard control(control_mutex_);
    if (!started_) return not_started(segment_.name);
    // Every problem here concerns one channel (BindingPlan); LCM has no failure of the whole
    // segment once started.
    BindingPlan plan(bindings);
    std::unordered_map<ChannelId, Channel> wanted;
    std::unordered_map<std::string, ChannelId> names;
    for (const ChannelBinding* b : plan.accepted()) {
      // A native binding names the LCM channel and carries the contents raw.
      const NativeBinding* native = b->spec.native_on(segment_.name);
      const std::string& name = native && native->lcm_channel ? *native->lcm_channel : b->spec.name;
      if (const Result<void> carried = check_binding(*b, name, names); !carried) {
        plan.refuse(*b, carried.error().text);
        continue;
      }
      names.emplace(name, b->id);
      Channel& c = wanted[b->id];
      c.id = b->id;
      c.name = name;
      c.subject = b->spec.subject;
      c.format = make_lcm_message_format(native && native->lcm_channel ? LcmEncoding::raw : b->spec.lcm_encoding);
      c.cls = b->spec.cls;
      if (b->role == HopRole::publisher) c.rx = true;
      if (b->role == HopRole::subscriber) c.tx = true;
    }
    // A channel refused in one role is not carried in the other either.
    std::erase_if(wanted, [&](const auto& entry) { return plan.refused(entry.first); });
    // The receive socket rejoins the group before a channel is received here again; if it cannot,
    // every received channel is refused (and, by the rule above, not sent either).
    bool receives = std::any_of(wanted.begin(), wanted.end(), [](const auto& c) { return c.second.rx; });
    if (receives && started_ && rx_fd_ >= 0) {
      if (const Result<void> joined = join_group(); !joined) {
        for (const ChannelBinding* b : plan.accepted()) {
          const auto entry = wanted.find(b->id);
          if (entry != wanted.end() && entry->second.rx)
            plan.refuse(*b, "cannot receive on this segment: " + joined.error().text);
        }
        std::erase_if(wanted, [&](const auto& entry) { return plan.refused(entry.first); });
        receives = false;
      }
    }
    // Swap the table (channels kept keep flowing through it). Reception is a lookup by name, no
    // subscription: every datagram of the group reaches the receive socket while it is a member.
    auto index = std::make_shared<ChannelIndex>();
    index->by_id = std::move(wanted);
    for (const auto& [id, channel] : index->by_id) index->by_name.emplace(channel.name, &channel);
    replace_table(ChannelTable{std::move(index), table_.current_for_publisher().sink});
    if (started_ && rx_fd_ >= 0 && !receives) leave_group();
    Status status = plan.status();
    if (!status.ok) log_.log(LogLevel::warning, prefix_ + status.error);
    return status;
  }

  SendStatus send(const OutboundEvent& event) override {
    const auto table = table_.read();
    const Channel* channel = transmitting(*table, event.channel);
    if (channel == nullptr) return transmit_.unbound();
    if (memq_.load(std::memory_order_relaxed)) return memq_sent();
    return transmit_.send(*channel, event);
  }

  // An egress lane's batch: each run of events of one class that fit one datagram goes out in
  // one sendmmsg, in order; a message that needs fragments goes alone.
  void send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) override {
    constexpr std::size_t kChunk = lcm_detail::SendBatch::kCapacity;
    const std::size_t n = std::min(events.size(), results.size());
    const auto table = table_.read();
    for (std::size_t from = 0; from < n; from += kChunk) {
      const std::size_t count = std::min(kChunk, n - from);
      std::array<const Channel*, kChunk> channels{};
      for (std::size_t i = 0; i < count; ++i) channels[i] = transmitting(*table, events[from + i].channel);
      if (memq_.load(std::memory_order_relaxed)) {
        for (std::size_t i = 0; i < count; ++i) results[from + i] = channels[i] ? memq_sent() : transmit_.unbound();
        continue;
      }
      transmit_.send_batch(events.subspan(from, count), std::span(channels.data(), count),
                           results.subspan(from, count));
    }
  }

  bool batches_sends() const override { return true; }

  HealthReport health() const override { return health_.get(); }

  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }  // multicast: unknowable

  AdapterStatistics statistics() const override {
    AdapterStatistics s = counters_.snapshot();
    LockGuard lock(own_count_mutex_);
    if (own_counting_ || own_dropped_before_ > 0) {
      s.transport.push_back(
          TransportCounter{"own_datagrams_dropped", own_dropped_before_ + (own_counting_ ? transmit_.own_drops() : 0)});
    }
    if (segment_.lcm.auth) {
      refusals_.report(s);
    }
    return s;
  }

  void stop() override {
    LockGuard control(control_mutex_);
    if (!started_) return;
    started_ = false;
    // No sink and no channel (stop() forgets the bindings: SegmentAdapter's lifecycle); returns
    // once the sends and the batch of received datagrams in flight have ended.
    replace_table(ChannelTable{});
    if (receiver_.running()) {
      receiver_.stop();
      ::close(std::exchange(rx_fd_, -1));
      member_ = false;
    }
    count_own_drops(false);  // after the last send (attach_sink above), before the next start resets the count
    transmit_.close();
    memq_.store(false, std::memory_order_relaxed);
    set_health(SegmentHealth::down, "stopped");
    log_.log(LogLevel::info, prefix_ + "stopped");
  }

 private:
  static bool receives_any(const ChannelTable& table) {
    const auto& channels = table.channels->by_id;
    return std::any_of(channels.begin(), channels.end(), [](const auto& c) { return c.second.rx; });
  }

  // Control thread (control_mutex_ held: one replacement at a time). Returns once no send or
  // received batch still reads the old table.
  void replace_table(ChannelTable next) COSMIC_REQUIRES(control_mutex_) {
    SnapshotTable<ChannelTable>::retire(table_.publish(std::move(next)));
  }

  // The receive socket is a member of the group only while a channel is received here. A segment
  // that only sends leaves it: what it sends no longer loops back to it (nothing to drop or cut,
  // nothing in the host's InErrors) and the group's other traffic never wakes its receive thread.
  Result<void> join_group() COSMIC_REQUIRES(control_mutex_) {
    if (member_) return {};
    transmit_.count_looped_back(true);  // before the join: the count never falls short
    if (Result<void> joined = lcm_detail::set_group_membership(rx_fd_, *rx_url_, true); !joined) {
      transmit_.count_looped_back(false);
      return joined;
    }
    member_ = true;
    log_.log(LogLevel::info, prefix_ + "a channel is received here: joined " + rx_url_->group);
    return {};
  }

  void leave_group() COSMIC_REQUIRES(control_mutex_) {
    // A socket that receives every group of the host (IP_MULTICAST_ALL could not be turned off)
    // would go on receiving ours while any other program is a member: it stays a member.
    if (!member_ || !may_leave_) return;
    if (const Result<void> left = lcm_detail::set_group_membership(rx_fd_, *rx_url_, false); !left) {
      log_.log(LogLevel::warning, prefix_ + "stays a member of the group (" + left.error().text + ")");
      return;
    }
    transmit_.count_looped_back(false);  // after the leave: the count never falls short
    member_ = false;
    log_.log(LogLevel::info,
             prefix_ + "no channel is received here: left " + rx_url_->group + " (joins it again when one is bound)");
  }

  // own_datagrams_dropped: the datagrams sent while the filter drops our own copies. The
  // transmitter counts from 0 again with every start; what earlier sockets sent is kept here.
  void count_own_drops(bool from_now_on) {
    LockGuard lock(own_count_mutex_);
    if (own_counting_) own_dropped_before_ += transmit_.own_drops();
    own_counting_ = from_now_on;
    if (from_now_on)
      log_.log(LogLevel::notice,
               prefix_ +
                   "while a channel is received here, its own datagrams loop back and its receive filter "
                   "drops them (own_datagrams: drop); each counts once in the host's UDP InErrors and "
                   "none in RcvbufErrors; cosmicctl segments --json reports them as own_datagrams_dropped");
  }

  static const Channel* transmitting(const ChannelTable& table, ChannelId id) {
    const auto& channels = table.channels->by_id;
    const auto it = channels.find(id);
    if (table.sink == nullptr || it == channels.end() || !it->second.tx) return nullptr;
    return &it->second;
  }

  Status fail_start(const std::string& why) {
    set_health(SegmentHealth::down, why);
    log_.log(LogLevel::error, prefix_ + why);
    return Status::failure(why);
  }

  void attach_sink(EventSink* sink) COSMIC_REQUIRES(control_mutex_) {
    replace_table(ChannelTable{table_.current_for_publisher().channels, sink});
  }

  // Whether binding `b` can be carried under LCM channel `name`, given the names taken so far.
  Result<void> check_binding(const ChannelBinding& b, const std::string& name,
                             const std::unordered_map<std::string, ChannelId>& names) const {
    if (name.empty()) return Error{"the native binding names no LCM channel"};
    if (Result<void> carried = check_transport_name(SegmentType::lcm, name); !carried) return carried;
    if (segment_.lcm.auth && (b.spec.native_on(segment_.name) != nullptr || b.spec.lcm_encoding == LcmEncoding::raw))
      return Error{"a raw LCM message cannot carry the authentication trailer this segment requires (auth)"};
    const auto taken = names.find(name);
    if (taken != names.end() && taken->second != b.id) {
      return Error{"LCM channel '" + name + "' is already bound by channel id " + std::to_string(taken->second)};
    }
    const auto same_id = std::find_if(names.begin(), names.end(), [&](const auto& n) { return n.second == b.id; });
    if (same_id != names.end() && same_id->first != name) {
      return Error{"channel id " + std::to_string(b.id) + " is already bound as LCM channel '" + same_id->first + "'"};
    }
    return {};
  }

  // The segment's receive thread: waits for datagrams or stop(), then reads all that are queued
  // in batches and hands each batch's events on under one reading of the table.
  void receive_loop(int fd) {
    lcm_detail::ReceiveBatch batch(kReceiveBatch);
    while (!receiver_.stopping()) {
      // After a failed read, a pause (stop() still ends it) rather than a spin on a socket that
      // keeps reporting data it cannot hand over.
      const bool failing = receive_failing_.load(std::memory_order_relaxed);
      pollfd fds[2] = {{failing ? -1 : fd, POLLIN, 0}, {receiver_.wake_fd(), POLLIN, 0}};
      const int ready = ::poll(fds, 2, failing ? kRetryAfterFailureMs : -1);
      if (ready < 0 && errno != EINTR) {
        note_receive_failure("poll", errno);
        continue;
      }
      if (fds[1].revents != 0) break;
      if (!failing && (ready <= 0 || (fds[0].revents & POLLIN) == 0)) continue;
      drain(fd, batch);
    }
  }

  // Reads what is queued in batches until a batch comes back short, stop() is asked for, or a
  // read fails.
  void drain(int fd, lcm_detail::ReceiveBatch& batch) {
    while (!receiver_.stopping()) {
      const int n = batch.receive(fd);
      if (n < 0) {
        note_receive_failure("recvmmsg", errno);
        return;
      }
      if (receive_failing_.exchange(false, std::memory_order_relaxed)) {
        set_health(SegmentHealth::up, "");
        log_.log(LogLevel::notice, prefix_ + "receiving again");
      }
      if (n == 0) return;
      handle_batch(batch, static_cast<std::size_t>(n));
      if (static_cast<std::size_t>(n) < batch.slots()) return;  // the queue is empty now
    }
  }

  void note_receive_failure(const char* call, int error) {
    if (receive_failing_.exchange(true, std::memory_order_relaxed)) return;
    const std::string what = std::string(call) + ": " + errno_text(error);
    set_health(SegmentHealth::degraded, what + " on " + segment_.lcm.url);
    log_.log(LogLevel::error, prefix_ + what);
  }

  // The socket's drop count is cumulative, 32 bits wide, and starts again with every socket; so
  // does the transmitter's count of our own datagrams the filter drops (own_drops(), raised before
  // each send and read after the drop count, so never short of the own drops in it). Their
  // difference modulo 2^32 is the overflow as far as this datagram knows, never more than the true
  // one; it is followed step by step (each step signed, far below 2^31 between two datagrams), so
  // neither counter's wrap is lost however many of our own were dropped meanwhile. The segment's
  // counter only rises to it.
  void note_kernel_drops(const lcm_detail::ReceiveBatch& batch) {
    const auto drops = batch.kernel_drops();
    if (!drops) return;
    const auto overflow_now = static_cast<std::uint32_t>(*drops - static_cast<std::uint32_t>(transmit_.own_drops()));
    overflow_total_ += static_cast<std::int32_t>(overflow_now - overflow_seen_);
    overflow_seen_ = overflow_now;
    if (overflow_total_ <= overflow_reported_) return;
    counters_.overflow_drops.fetch_add(static_cast<std::uint64_t>(overflow_total_ - overflow_reported_),
                                       std::memory_order_relaxed);
    overflow_reported_ = overflow_total_;
  }

  // Receive thread only.
  void handle_batch(const lcm_detail::ReceiveBatch& batch, std::size_t count) {
    note_kernel_drops(batch);
    // One reading of both clocks for the batch: arrival times are converted with it.
    const std::int64_t steady = steady_now().count();
    const std::int64_t realtime_now =
        std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
    const auto reading = table_.read();
    const ChannelTable& table = *reading;
    if (table.sink == nullptr) return;
    for (std::size_t i = 0; i < count; ++i) {
      const Endpoint from = batch.sender(i);
      if (transmit_.is_own(from)) continue;  // ours, looped back (emptied by a cutting filter, or none attached)
      const auto parsed = batch.truncated(i) ? std::nullopt : parse_lcm_datagram(batch.datagram(i));
      if (!parsed) {
        counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);  // not LCM's, or damaged
        continue;
      }
      std::int64_t arrival = batch.arrival_realtime_ns(i);
      if (arrival == 0) arrival = realtime_now;
      const Nanos received_at = steady_arrival(arrival, Nanos(steady), realtime_now);
      if (!parsed->fragment) {
        deliver(table, from, parsed->channel, parsed->data, received_at, arrival);
        continue;
      }
      reassemble(table, from, *parsed, received_at, arrival);
    }
  }

  // One fragment. Messages of channels not received here are skipped whole (fragment 0 names the
  // channel; the fragments after it do not); what the reassembler refuses or gives up is a
  // receive error, as a malformed datagram is.
  void reassemble(const ChannelTable& table, Endpoint from, const LcmDatagram& fragment, Nanos received_at,
                  std::int64_t arrival) {
    if (!fragment.channel.empty() && !receives(table, fragment.channel)) {
      reassembler_.skip(from.key(), fragment.sequence);
      return;
    }
    const std::uint64_t abandoned_before = reassembler_.abandoned();
    LcmReassembler::Outcome outcome = LcmReassembler::Outcome::refused;
    try {
      outcome = reassembler_.add(from.key(), fragment);
    } catch (const std::bad_alloc&) {
      outcome = LcmReassembler::Outcome::refused;  // no memory for the message: it is lost
    }
    const std::uint64_t lost =
        reassembler_.abandoned() - abandoned_before + (outcome == LcmReassembler::Outcome::refused);
    if (lost != 0) counters_.receive_errors.fetch_add(lost, std::memory_order_relaxed);
    if (outcome == LcmReassembler::Outcome::complete)
      deliver(table, from, reassembler_.channel(), reassembler_.payload(), received_at, arrival);
  }

  static bool receives(const ChannelTable& table, std::string_view name) {
    const auto it = table.channels->by_name.find(name);
    return it != table.channels->by_name.end() && it->second->rx;
  }

  // One whole message of LCM channel `name`, from the receive thread's reading of `table`.
  void deliver(const ChannelTable& table, Endpoint from, std::string_view name, std::span<const std::uint8_t> bytes,
               Nanos received_at, std::int64_t arrival_realtime_ns) {
    const auto it = table.channels->by_name.find(name);
    if (it == table.channels->by_name.end() || !it->second->rx) return;  // not bound for reception here
    const Channel& channel = *it->second;
    counters_.received.fetch_add(1, std::memory_order_relaxed);
    if (verifier_) {
      const LcmAuthCheck checked = verifier_->check(name, bytes, arrival_realtime_ns);
      if (checked.verdict != LcmAuthVerdict::authentic) {
        table.sink->on_problem(channel.id, refusals_.refuse(channel.name, from.text(), checked, received_at));
        return;
      }
      bytes = bytes.first(checked.message_size);
    }
    InboundEvent event;
    event.channel = channel.id;
    event.received_at = received_at;
    // An envelope with our origin that is not our own datagram (a loop through another gateway,
    // or a spoof) goes on to the router, which counts it (ingress check: own origin).
    const LcmArrival arrival{channel.subject, arrival_realtime_ns};
    if (!channel.format->decode(bytes, arrival, segment_.max_message_size, event)) {
      counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
      table.sink->on_problem(channel.id, InboundProblem::decode_error);
      return;
    }
    table.sink->on_event(event);
  }

  // memq://: nothing to send on, and nothing lost by it.
  SendStatus memq_sent() {
    counters_.sent.fetch_add(1, std::memory_order_relaxed);
    return SendStatus::sent;
  }

  void set_health(SegmentHealth state, std::string detail) { health_.set(state, std::move(detail)); }

  const SegmentSpec segment_;
  Logger& log_;
  const std::string prefix_;  // "LCM segment NAME: " (cosmic/log_prefix.hpp)
  AdapterCounters counters_;
  HealthCell health_;
  std::atomic<bool> receive_failing_{false};  // a read failed; cleared by the next that works

  Mutex control_mutex_;
  bool started_ COSMIC_GUARDED_BY(control_mutex_) = false;
  ReceiveThread receiver_;  // runs receive_loop(); stop() ends it through its eventfd
  int rx_fd_ COSMIC_GUARDED_BY(control_mutex_) = -1;
  std::optional<LcmUrl> rx_url_ COSMIC_GUARDED_BY(control_mutex_);
  bool member_ COSMIC_GUARDED_BY(control_mutex_) = false;     // rx_fd_ is a member of the group
  bool may_leave_ COSMIC_GUARDED_BY(control_mutex_) = false;  // leaving stops all of the group's datagrams
  // memq://: set by start() before the sink is attached, cleared by stop() after it is detached.
  std::atomic<bool> memq_{false};

  SnapshotTable<ChannelTable> table_;

  lcm_detail::LcmTransmitter transmit_;
  // Receive thread only (set by start() before the thread starts).
  LcmReassembler reassembler_;
  std::optional<LcmAuthVerifier> verifier_;  // on a segment with auth
  lcm_detail::LcmAuthRefusals refusals_;     // what it refused
  std::uint32_t overflow_seen_ = 0;          // drops less own drops, modulo 2^32, at the last report
  std::int64_t overflow_total_ = 0;          // ... followed without wrapping
  std::int64_t overflow_reported_ = 0;       // what overflow_drops got from this socket so far

  mutable Mutex own_count_mutex_;  // statistics() from any thread; start()/stop() write
  bool own_counting_ COSMIC_GUARDED_BY(own_count_mutex_) = false;
  std::uint64_t own_dropped_before_ COSMIC_GUARDED_BY(own_count_mutex_) = 0;
};

}  // namespace

std::unique_ptr<SegmentAdapter> make_lcm_adapter(const SegmentSpec& segment, const GatewayIdentity& /*self*/,
                                                 Logger& log) {
  return std::make_unique<LcmAdapter>(segment, log);
}

}  // namespace cosmic

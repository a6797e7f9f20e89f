// A replay segment (cosmic/replay_adapter.hpp).
#include "cosmic/replay_adapter.hpp"

#include <pthread.h>

#include "cosmic/thread_policy.hpp"

#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <thread>

#include "cosmic/binding_plan.hpp"
#include "cosmic/cdr_representation.hpp"
#include "cosmic/json_event_reader.hpp"
#include "cosmic/mapped_file.hpp"
#include "cosmic/mcap_reader.hpp"
#include "cosmic/router_stats.hpp"
#include "cosmic/steady_clock.hpp"

namespace cosmic {
namespace {

using Clock = std::chrono::steady_clock;

std::string micros(Nanos value) { return std::to_string(value.count() / 1000) + " us"; }

class ReplayAdapter final : public SegmentAdapter {
 public:
  ReplayAdapter(SegmentSpec spec, Logger& log) : spec_(std::move(spec)), log_(log) {}
  ~ReplayAdapter() override { stop(); }

  Status start(EventSink& sink) override {
    std::unique_lock lock(mutex_);
    if (sink_ != nullptr) return Status::failure("segment " + spec_.name + " already started");
    auto file = MappedFile::open(spec_.replay.file);
    if (!file) {
      health_ = HealthReport{SegmentHealth::down, file.error().text};
      return Status::failure(file.error().text);
    }
    file_ = std::move(file).value();
    sink_ = &sink;
    // A segment declared real-time plays at the receive threads' priority and on their CPUs.
    if (spec_.realtime) policy_ = sink.receive_thread_policy();
    stopping_ = false;
    health_ = HealthReport{SegmentHealth::up, "waiting for a channel of the recording to be bound"};
    thread_ = std::thread([this] { run(); });
    return Status::success();
  }

  Status configure(std::span<const ChannelBinding> bindings) override {
    std::lock_guard lock(mutex_);
    if (sink_ == nullptr) return not_started(spec_.name);
    BindingPlan plan(bindings);
    std::map<std::string, Bound> bound;
    for (const ChannelBinding* b : plan.accepted()) {
      if (b->role != HopRole::publisher) {
        plan.refuse(*b, "a replay segment only publishes: nothing can be sent into a recording");
        continue;
      }
      Bound& entry = bound[b->spec.name];
      entry.id = b->id;
      // A typed channel was recorded as CDR or JSON: read back into the compact layout the router
      // takes. A type without a CDR form (a conditional field) was recorded as JSON.
      if (b->spec.type) {
        entry.json = std::make_shared<const JsonEventReader>(*b->spec.type);
        if (auto cdr = CdrRepresentation::make(*b->spec.type, DdsRepresentation::xcdr1, CdrExtensibility::final_type))
          entry.cdr = std::make_shared<const CdrRepresentation>(std::move(cdr).value());
      }
    }
    if (bound_.empty() && !bound.empty()) ++pass_request_;  // carrying again: a new pass from the start
    bound_ = std::move(bound);
    wake_.notify_all();
    return plan.status();
  }

  SendStatus send(const OutboundEvent&) override { return SendStatus::failed; }

  HealthReport health() const override {
    std::lock_guard lock(mutex_);
    return health_;
  }

  AdapterStatistics statistics() const override {
    std::lock_guard lock(mutex_);
    AdapterStatistics out;
    out.received = replayed_;
    out.receive_errors = undecodable_;
    out.transport = {{"passes", passes_},
                     {"lateness_p50_ns", static_cast<std::uint64_t>(lateness_->quantile(0.50).count())},
                     {"lateness_p99_ns", static_cast<std::uint64_t>(lateness_->quantile(0.99).count())},
                     {"lateness_max_ns", static_cast<std::uint64_t>(lateness_->max().count())}};
    return out;
  }

  std::optional<std::size_t> matched_peers(ChannelId) const override { return std::nullopt; }

  void stop() override {
    {
      std::lock_guard lock(mutex_);
      if (sink_ == nullptr) return;
      stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
    std::lock_guard lock(mutex_);
    sink_ = nullptr;
    bound_.clear();
    file_.reset();
    health_ = HealthReport{SegmentHealth::down, "stopped"};
  }

 private:
  // The pass in progress: where the recording's time starts and when it started here.
  struct Pass {
    std::optional<std::uint64_t> first_log_time;  // of the selection, before start_offset
    std::uint64_t origin_log_time = 0;            // first_log_time + start_offset
    Clock::time_point started{};
    Clock::time_point last_due{};  // of the last event delivered
    std::uint64_t delivered = 0;
    bool routed = false;                            // the router took the pass's first event's channel from here
    std::map<std::string, Clock::time_point> sent;  // by channel: when its last event went
  };

  void run() {
    ThreadPolicy policy = policy_;
    policy.name = "replay:" + spec_.name;
    for (const std::string& problem : apply_thread_policy(policy))
      log_.log(LogLevel::warning, "segment " + spec_.name + ": could not get " + problem);
    std::uint64_t played_request = 0;
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stopping_ || (!bound_.empty() && pass_request_ != played_request); });
        if (stopping_) return;
        played_request = pass_request_;
      }
      Clock::time_point start = Clock::now();
      for (;;) {
        Pass pass;
        pass.started = start;
        if (!play_pass(played_request, pass)) break;
        std::lock_guard lock(mutex_);
        ++passes_;
        if (!spec_.replay.loop || pass.delivered == 0 || stopping_) {
          health_ = HealthReport{
              SegmentHealth::up,
              (pass.delivered == 0 ? "finished: nothing at or after start_offset; " : "finished: ") + summary_locked()};
          break;
        }
        // The next pass keeps the recording's pace across the seam: its first event one tightest
        // spacing after the last one of this pass, never back to back.
        start = std::max(Clock::now(), pass.last_due + loop_gap());
      }
    }
  }

  // The tightest recorded spacing of `channel` at the replay's speed (0 with fewer than two events).
  Clock::duration tightest_gap(const std::string& channel) const {
    const ReplayStream* stream = spec_.replay.stream(channel);
    if (!stream || stream->events < 2) return Clock::duration::zero();
    return std::chrono::nanoseconds(
        static_cast<std::int64_t>(static_cast<double>(stream->tightest.count()) / spec_.replay.speed));
  }

  // The smallest recorded spacing of the selected channels at the replay's speed, at least 1 ms.
  Clock::duration loop_gap() const {
    Nanos tightest{0};
    for (const ReplayStream& stream : spec_.replay.streams)
      if (stream.events >= 2 && (tightest.count() == 0 || stream.tightest < tightest)) tightest = stream.tightest;
    const auto gap =
        std::chrono::nanoseconds(static_cast<std::int64_t>(static_cast<double>(tightest.count()) / spec_.replay.speed));
    return std::max<Clock::duration>(gap, std::chrono::milliseconds(1));
  }

  // One pass over the recording; false when it was cut short (stopped, unbound, damaged).
  bool play_pass(std::uint64_t request, Pass& pass) {
    {
      std::lock_guard lock(mutex_);
      lateness_ = std::make_unique<LatencyHistogram>();
      health_ = HealthReport{SegmentHealth::up, "replaying " + spec_.replay.file};
    }
    const auto on_message = [&](const McapMessageView& m, const McapChannel& channel) -> Result<void> {
      return play(pass, request, m, channel);
    };
    const auto scanned = scan_mcap(file_->bytes(), on_message);
    if (scanned) return true;
    std::lock_guard lock(mutex_);
    if (!stopping_ && request == pass_request_ && !bound_.empty()) {
      health_ = HealthReport{SegmentHealth::degraded, "the recording cannot be read on: " + scanned.error().text};
      log_.log(LogLevel::error, "segment " + spec_.name + ": " + health_.detail);
    }
    return false;
  }

  Result<void> play(Pass& pass, std::uint64_t request, const McapMessageView& m, const McapChannel& channel) {
    if (!spec_.replay.selects(channel.topic)) return {};
    if (!pass.first_log_time) {
      pass.first_log_time = m.log_time;
      pass.origin_log_time = m.log_time + static_cast<std::uint64_t>(spec_.replay.start_offset.count());
    }
    if (m.log_time < pass.origin_log_time) return {};
    // Clamped: a third party's file may hold absurd times (the loader bounds the selection's span).
    const double offset = std::min(static_cast<double>(m.log_time - pass.origin_log_time) / spec_.replay.speed, 1e17);
    Clock::time_point due = pass.started + std::chrono::nanoseconds(static_cast<std::int64_t>(offset));
    // Never closer to the channel's previous event than the recording's tightest spacing at this
    // speed, the rate admission granted: a replay that fell behind (a late wake-up on a busy host)
    // catches up no faster than that, so the channel's rate policing never cuts a recorded event.
    Clock::time_point send_at = due;
    if (const auto last = pass.sent.find(channel.topic); last != pass.sent.end())
      send_at = std::max(due, last->second + tightest_gap(channel.topic));
    Bound target;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, send_at, [&] { return stopping_ || request != pass_request_ || bound_.empty(); });
      if (stopping_ || request != pass_request_ || bound_.empty()) return Error{"cut short"};
      const auto it = bound_.find(channel.topic);
      if (it == bound_.end()) return {};
      target = it->second;
      if (!pass.routed) {
        // The pass begins when the gateway routes from here (a replacement's hop opens ahead of its
        // switch, which may wait seconds for other publishers to match): its timing shifts by the wait.
        const Clock::time_point asked = Clock::now();
        while (!sink_->routes(target.id)) {
          wake_.wait_for(lock, std::chrono::milliseconds(1),
                         [&] { return stopping_ || request != pass_request_ || bound_.empty(); });
          if (stopping_ || request != pass_request_ || bound_.empty()) return Error{"cut short"};
        }
        pass.routed = true;
        const Clock::duration shift = Clock::now() - asked;
        pass.started += shift;
        due += shift;
        send_at += shift;
      }
    }
    std::span<const std::uint8_t> contents = m.data;
    if (target.json) {
      const auto size = read_typed(target, channel.message_encoding, m.data);
      if (!size) {
        std::lock_guard lock(mutex_);
        ++undecodable_;  // recorded under another type, or neither as CDR nor as JSON
        return {};
      }
      contents = std::span<const std::uint8_t>(compact_).first(*size);
    }
    // No identity of its own: the router makes this gateway its origin and numbers it.
    const InboundEvent event{target.id, EventHeader{}, contents, steady_now(),
                             FormatIdentity{false, false, false, false}};
    sink_->on_event(event);
    const Clock::time_point sent = Clock::now();
    pass.sent[channel.topic] = sent;
    const Nanos late = std::chrono::duration_cast<Nanos>(sent - due);
    pass.last_due = due;
    ++pass.delivered;
    std::lock_guard lock(mutex_);
    lateness_->record(std::max(late, Nanos(0)));
    ++replayed_;
    return {};
  }

  std::string summary_locked() const {
    return std::to_string(replayed_) + " events in " + std::to_string(passes_) + " pass(es); lateness p50 " +
           micros(lateness_->quantile(0.5)) + ", p99 " + micros(lateness_->quantile(0.99)) + ", max " +
           micros(lateness_->max());
  }

  const SegmentSpec spec_;
  Logger& log_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  EventSink* sink_ = nullptr;  // set while started
  bool stopping_ = false;
  std::unique_ptr<MappedFile> file_;
  // A channel bound here: its id, and for a typed channel the reader of its recorded JSON.
  struct Bound {
    ChannelId id = kNoChannel;
    std::shared_ptr<const JsonEventReader> json;
    std::shared_ptr<const CdrRepresentation> cdr;  // null when the type has no CDR form
  };

  // A typed channel's recorded message read into compact_: CDR (any plain encoding
  // CdrRepresentation reads) or JSON.
  std::optional<std::size_t> read_typed(const Bound& target, const std::string& encoding,
                                        std::span<const std::uint8_t> data) {
    compact_.resize(target.json->max_compact_size());
    if (encoding == "cdr" && target.cdr) {
      const Conversion read = target.cdr->to_compact(data, compact_);
      return read.ok() ? std::optional(read.size) : std::nullopt;
    }
    if (encoding != "json") return std::nullopt;
    return target.json->read_unexplained(std::string_view(reinterpret_cast<const char*>(data.data()), data.size()),
                                         compact_);
  }

  std::map<std::string, Bound> bound_;  // by channel name, publisher bindings
  std::vector<std::uint8_t> compact_;   // the replay thread's: a typed event read back
  std::uint64_t pass_request_ = 0;      // bumped when the segment starts carrying channels again
  std::unique_ptr<LatencyHistogram> lateness_ = std::make_unique<LatencyHistogram>();  // of the current pass
  std::uint64_t replayed_ = 0;
  std::uint64_t undecodable_ = 0;  // events of a bound typed channel that did not read back
  std::uint64_t passes_ = 0;
  HealthReport health_{SegmentHealth::down, "not started"};
  std::thread thread_;
  ThreadPolicy policy_;  // start()'s: the receive threads' when the segment is declared real-time
};

}  // namespace

std::unique_ptr<SegmentAdapter> make_replay_adapter(const SegmentSpec& segment, Logger& log) {
  return std::make_unique<ReplayAdapter>(segment, log);
}

}  // namespace cosmic

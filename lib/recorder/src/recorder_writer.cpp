// The recorder's writer thread (cosmic/recorder.hpp): takes the queued events, writes them into the
// current MCAP file, rotates, flushes chunks, and answers start and stop.
#include <time.h>

#include <cstring>
#include <filesystem>

#include "cosmic/recorder.hpp"
#include "cosmic/thread_policy.hpp"
#include "recorder_shared.hpp"
#include "recording_file.hpp"

namespace cosmic {

using recorder_detail::QueuedHead;
using recorder_detail::RecordingFile;
using recorder_detail::TakenEvent;

namespace {

// How far the UTC clock is ahead of CLOCK_MONOTONIC now. An event's arrival on the UTC clock is its
// monotonic arrival plus this, read once per batch the writer takes instead of twice per event on
// the ingress thread: the two clocks drift apart by at most NTP's slew (500 ppm) meanwhile, 10 us
// over the writer's 20 ms poll.
std::int64_t utc_minus_monotonic_ns() {
  timespec utc{};
  timespec monotonic{};
  ::clock_gettime(CLOCK_MONOTONIC, &monotonic);
  ::clock_gettime(CLOCK_REALTIME, &utc);
  return (static_cast<std::int64_t>(utc.tv_sec) - monotonic.tv_sec) * 1'000'000'000 + (utc.tv_nsec - monotonic.tv_nsec);
}

// Whether a slot named in both tables names two different segments (a slot named in one only is a
// segment added or removed: the streams found so far stay right).
bool renamed(const std::vector<std::string>& before, const std::vector<std::string>& after) {
  for (std::size_t i = 0; i < before.size() && i < after.size(); ++i)
    if (!before[i].empty() && !after[i].empty() && before[i] != after[i]) return true;
  return false;
}

}  // namespace

class Recorder::Writer {
 public:
  using Clock = std::chrono::steady_clock;
  // How often the queue is emptied; what it must hold meanwhile is `memory`'s business.
  static constexpr std::chrono::milliseconds kPoll{20};
  // The open chunk is closed at least this often: what a crash can lose of what was queued.
  static constexpr std::chrono::seconds kFlushEvery{1};
  // After a failed open or write, the next file is tried this much later.
  static constexpr std::chrono::seconds kRetryEvery{5};
  static constexpr std::size_t kBatch = 4096;
  static constexpr std::size_t kDrainBatches = 8;

  explicit Writer(Recorder& recorder) : recorder_(recorder), shared_(*recorder.shared_) {}

  void loop() {
    for (const std::string& problem : apply_thread_policy(ThreadPolicy{"record", 0, 19, {}}))
      recorder_.log_.log(LogLevel::warning, "recorder: could not get " + problem);
    bool behind = false;
    for (;;) {
      bool quit = false;
      std::uint64_t generation = 0;
      bool want = false;
      {
        std::unique_lock lock(shared_.mutex);
        // Behind (the last drain stopped at its budget): no pause, only the requests are looked at.
        shared_.wake.wait_for(lock, behind ? std::chrono::milliseconds(0) : kPoll,
                              [&] { return shared_.quit || shared_.generation != seen_generation_; });
        quit = shared_.quit;
        generation = shared_.generation;
        want = shared_.want_recording;
        spec_ = shared_.spec;
        channels_ = shared_.channels;
        // Streams are found by segment slot: a slot that now names another segment needs new ones.
        if (file_ && segments_ && renamed(*segments_, *shared_.segments)) file_->forget_streams();
        segments_ = shared_.segments;
      }
      // What was queued before a stop still belongs to the recording: all of it, not one budget.
      const bool stopping = quit || (generation != seen_generation_ && !want);
      behind = drain(stopping ? whole_queue_batches() : kDrainBatches);
      const auto now = Clock::now();
      if (generation != seen_generation_) act_on(want, now);
      if (recording_) keep_up(now);
      publish(generation);
      if (quit) break;
    }
    finish_file();
    publish(seen_generation_);
  }

 private:
  // Takes what is queued, at most `batches` batches: under a flood the queue never empties, and
  // start, stop, flushing and rotation must still be served. True when it stopped at that budget.
  bool drain(std::size_t batches) {
    for (std::size_t batch = 0; batch < batches; ++batch) {
      utc_offset_ns_ = utc_minus_monotonic_ns();
      if (recorder_.ring_.read([this](std::span<const std::uint8_t> record) { take(record); }, kBatch) < kBatch)
        return false;
    }
    return true;
  }

  // Batches enough to take everything queued now (and what producers add meanwhile, up to one queue's
  // worth more, so a flood cannot hold a stop back).
  std::size_t whole_queue_batches() const {
    return recorder_.ring_.capacity() / RecordRing::kMinRecordBytes / kBatch + 1;
  }

  void take(std::span<const std::uint8_t> record) {
    if (!recording_) return;  // offered just before a stop: not part of any recording
    QueuedHead head{};
    std::memcpy(&head, record.data(), sizeof head);
    const std::span<const std::uint8_t> payload = record.subspan(sizeof head);
    const auto found = channels_->find(head.channel);
    if (found == channels_->end()) {
      ++dropped_invalid_;
      return;
    }
    if (!file_) {
      ++dropped_failed_;
      return;
    }
    const RecordedChannel& channel = *found->second;
    TakenEvent event;
    event.channel = head.channel;
    event.segment_slot = head.segment;
    event.segment = head.segment < segments_->size() ? &(*segments_)[head.segment] : nullptr;
    event.origin = head.origin;
    event.sequence = head.sequence;
    event.created_ns = head.created_ns;
    event.arrival_ns = head.received_ns + utc_offset_ns_;
    event.contents = payload;
    if (!encode(channel, event.contents)) {
      ++dropped_invalid_;  // an event of the channel's previous type, queued before a rebind
      return;
    }
    const std::uint64_t taken = file_->writer().message_count();
    const auto written = file_->write(channel, event);
    if (!written) {
      // In the chunk whose write failed, the event is counted with that chunk's (close_file).
      if (file_->writer().message_count() == taken) ++dropped_failed_;
      fail(written.error().text, Clock::now());
    } else if (!written.value()) {
      ++dropped_invalid_;
    } else if (file_->writer().bytes_written() >= spec_.rotate_size) {
      rotate(Clock::now());  // here, not only between polls: one poll may bring a file's worth
    }
  }

  // A typed channel's event replaced by what is recorded of it (CDR or JSON, in this thread's
  // buffer, which grows to the largest a channel needs and is then reused); false when it is not
  // an event of the channel's type. An untyped channel's stays as it came.
  bool encode(const RecordedChannel& channel, std::span<const std::uint8_t>& contents) {
    if (channel.cdr) {
      if (encoded_.size() < channel.cdr->max_wire_size()) encoded_.resize(channel.cdr->max_wire_size());
      const Conversion converted = channel.cdr->from_compact(contents, encoded_);
      if (!converted.ok()) return false;
      contents = std::span<const std::uint8_t>(encoded_).first(converted.size);
    } else if (channel.json) {
      if (encoded_.size() < channel.json->max_size()) encoded_.resize(channel.json->max_size());
      const auto size = channel.json->write(
          contents, std::span<char>(reinterpret_cast<char*>(encoded_.data()), channel.json->max_size()));
      if (!size) return false;
      contents = std::span<const std::uint8_t>(encoded_).first(*size);
    }
    return true;
  }

  void rotate(Clock::time_point now) {
    finish_file();
    open_file(now);
  }

  void act_on(bool want, Clock::time_point now) {
    if (want && !recording_) {
      recording_ = true;
      last_error_.clear();
      open_file(now);
      // A start that cannot open its first file is refused (Recorder::start reports why).
      if (!file_) recording_ = false;
    } else if (!want && recording_) {
      finish_file();
      recording_ = false;
    }
  }

  void keep_up(Clock::time_point now) {
    if (!file_) {
      if (now >= next_retry_) open_file(now);
      return;
    }
    const McapWriter& writer = file_->writer();
    const bool full = writer.bytes_written() >= spec_.rotate_size;
    const bool old = now - opened_ >= spec_.rotate_duration;
    if (full || old) {
      rotate(now);
    } else if (now >= next_flush_) {
      if (auto flushed = file_->flush_chunk(); !flushed) fail(flushed.error().text, now);
      next_flush_ = now + kFlushEvery;
    }
  }

  void open_file(Clock::time_point now) {
    const std::int64_t utc =
        std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
    std::error_code ignored;
    std::filesystem::create_directories(spec_.directory, ignored);
    const auto path_for = [&](std::uint64_t n) {
      return (std::filesystem::path(spec_.directory) /
              recorder_detail::recording_file_name(recorder_.gateway_, utc, n, ".mcap"))
          .string();
    };
    auto file = RecordingFile::create(path_for(++numbered_), spec_, recorder_.gateway_, utc);
    // A file of that name exists (a cosmicd restarted within the same second): the next number.
    for (int tries = 0; !file && file.error().code == EEXIST && tries < 1000; ++tries)
      file = RecordingFile::create(path_for(++numbered_), spec_, recorder_.gateway_, utc);
    if (!file) {
      fail(file.error().text, now);
      return;
    }
    file_ = std::move(file).value();
    opened_ = now;
    file_dropped_full_ = recorder_.dropped_full_.load(std::memory_order_relaxed);
    file_dropped_failed_ = dropped_failed_;
    file_dropped_invalid_ = dropped_invalid_;
    next_flush_ = now + kFlushEvery;
  }

  void finish_file() {
    if (auto closed = close_file(); !closed) {
      last_error_ = closed.error().text;
      recorder_.log_.log(LogLevel::error, "recorder: " + last_error_ + "; the file keeps what was written");
    }
  }

  // Ends the current file, if any, with what was dropped while it was open, and adds what it holds
  // to the totals.
  Result<void> close_file() {
    if (!file_) return {};
    const std::uint64_t full = recorder_.dropped_full_.load(std::memory_order_relaxed);
    const McapMap closing{{"dropped_queue_full", std::to_string(full - file_dropped_full_)},
                          {"dropped_not_written", std::to_string(dropped_failed_ - file_dropped_failed_)},
                          {"dropped_invalid", std::to_string(dropped_invalid_ - file_dropped_invalid_)}};
    auto finished = file_->finish(closing);
    const McapWriter& writer = file_->writer();
    // A chunk the file could not take (a failed write, here or before) lost its messages.
    const std::uint64_t lost = writer.chunk_message_count();
    dropped_failed_ += lost;
    messages_ += writer.message_count() - lost;
    bytes_ += writer.bytes_written();
    uncompressed_ += writer.uncompressed_bytes();
    compressed_ += writer.compressed_bytes();
    ++files_;
    file_.reset();
    return finished;
  }

  // The file cannot go on: what it holds stays (readable up to its last whole chunk), the events
  // count as dropped until the next file opens.
  void fail(const std::string& why, Clock::time_point now) {
    if (why != last_error_) recorder_.log_.log(LogLevel::error, "recorder: " + why);
    last_error_ = why;
    auto closed = close_file();
    static_cast<void>(closed);  // already failing: the first reason is the one that counts
    next_retry_ = now + kRetryEvery;
  }

  void publish(std::uint64_t generation) {
    const std::lock_guard lock(shared_.mutex);
    RecorderStatus& s = shared_.status;
    s.recording = recording_;
    s.directory = spec_.directory;
    s.file = file_ ? file_->path() : std::string();
    s.files = files_;
    const McapWriter* writer = file_ ? &file_->writer() : nullptr;
    s.messages = messages_ + (writer ? writer->message_count() : 0);
    s.bytes = bytes_ + (writer ? writer->bytes_written() : 0);
    s.uncompressed = uncompressed_ + (writer ? writer->uncompressed_bytes() : 0);
    s.compressed = compressed_ + (writer ? writer->compressed_bytes() : 0);
    s.dropped_failed = dropped_failed_;
    s.dropped_invalid = dropped_invalid_;
    s.last_error = last_error_;
    if (generation != seen_generation_) {
      seen_generation_ = generation;
      shared_.acked = generation;
      shared_.acknowledged.notify_all();
    }
  }

  Recorder& recorder_;
  Shared& shared_;
  bool recording_ = false;
  std::uint64_t seen_generation_ = 0;
  RecordingSpec spec_;
  std::shared_ptr<const Shared::ChannelTable> channels_;
  std::shared_ptr<const std::vector<std::string>> segments_;
  std::unique_ptr<RecordingFile> file_;
  Clock::time_point opened_{};
  Clock::time_point next_flush_{};
  Clock::time_point next_retry_{};
  std::uint64_t numbered_ = 0;
  std::uint64_t files_ = 0, messages_ = 0, bytes_ = 0, uncompressed_ = 0, compressed_ = 0;
  std::uint64_t dropped_failed_ = 0, dropped_invalid_ = 0;
  // The drop counts when the current file was opened: its own drops are the difference.
  std::uint64_t file_dropped_full_ = 0, file_dropped_failed_ = 0, file_dropped_invalid_ = 0;
  std::string last_error_;
  std::vector<std::uint8_t> encoded_;
  std::int64_t utc_offset_ns_ = 0;  // utc_minus_monotonic_ns() for the batch being taken
};

void Recorder::run() { Writer(*this).loop(); }

}  // namespace cosmic

// CAN logs in candump -l format (cosmic/candump_recorder.hpp): the taps' side, the control side and
// the writer thread.
#include "cosmic/candump_recorder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>

#include "cosmic/arrival_clock.hpp"
#include "cosmic/candump_log.hpp"
#include "cosmic/posix_call.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/thread_policy.hpp"
#include "recording_file.hpp"

namespace cosmic {
namespace {

using recorder_detail::recording_file_name;
using recorder_detail::write_all;

// How often the queue is emptied into the files: how late a line reaches its file, at most.
constexpr std::chrono::milliseconds kPoll{20};
// After a failed open or write, a segment's next file is tried this much later.
constexpr Nanos kRetryEvery{std::chrono::seconds(5)};
// A segment's lines are written once this many bytes wait, besides at every poll.
constexpr std::size_t kWriteAt = 64 * 1024;
constexpr std::size_t kBatch = 4096;

// Copied into the queue in front of the frame's bytes (plain bytes, this process only).
struct QueuedFrame {
  std::uint64_t slot_and_session;
  std::int64_t utc_ns;
};

}  // namespace

struct CandumpRecorder::SegmentLog {
  CandumpSegment segment;
  OwnedFd fd;
  std::string path;
  Nanos opened{0};
  Nanos retry_at{0};
  std::uint64_t bytes_in_file = 0;
  std::string pending;  // lines not yet written
  std::uint64_t pending_lines = 0;
};

void CandumpTap::on_wire(const WireUnit& unit) noexcept {
  CandumpRecorder* recorder = recorder_.load(std::memory_order_acquire);
  if (recorder) recorder->offer(slot_and_session_.load(std::memory_order_acquire), unit);
}

CandumpRecorder::CandumpRecorder(const RecordingSpec& spec, std::string gateway, Logger& log)
    : gateway_(std::move(gateway)), log_(log), ring_(spec.memory / 4), spec_(spec) {
  thread_ = std::thread([this] { run(); });
}

CandumpRecorder::~CandumpRecorder() {
  stop();
  {
    const std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void CandumpRecorder::offer(std::uint64_t slot_and_session, const WireUnit& unit) noexcept {
  const QueuedFrame head{slot_and_session, unit.utc_ns};
  const std::span<const std::uint8_t> parts[] = {{reinterpret_cast<const std::uint8_t*>(&head), sizeof head},
                                                 unit.bytes};
  if (!ring_.try_write(parts)) dropped_full_.fetch_add(1, std::memory_order_relaxed);
}

Result<void> CandumpRecorder::start(std::vector<CandumpSegment> segments) {
  stop();
  const std::lock_guard lock(mutex_);
  std::error_code failed;
  std::filesystem::create_directories(spec_.directory, failed);
  if (failed) return Error{"cannot make the recording directory " + spec_.directory + ": " + failed.message()};
  ++session_;
  logs_.clear();
  logs_.reserve(segments.size());
  for (CandumpSegment& segment : segments) {
    logs_.push_back(SegmentLog{});
    logs_.back().segment = std::move(segment);
    if (auto opened = open(logs_.back()); !opened) {
      for (SegmentLog& log : logs_) close(log);
      logs_.clear();
      return std::move(opened).error();
    }
  }
  for (std::size_t slot = 0; slot < logs_.size(); ++slot) {
    CandumpTap& tap = *logs_[slot].segment.tap;
    tap.slot_and_session_.store(std::uint64_t{session_} << 32 | slot, std::memory_order_release);
    tap.recorder_.store(this, std::memory_order_release);
  }
  return {};
}

void CandumpRecorder::stop() {
  const std::lock_guard lock(mutex_);
  if (logs_.empty()) return;
  for (SegmentLog& log : logs_) log.segment.tap->recorder_.store(nullptr, std::memory_order_release);
  // What was queued before the taps let go still belongs to the recording; a frame a tap is
  // queueing right now finds no slot next time and is ignored.
  write_queued(false);
  for (SegmentLog& log : logs_) close(log);
  logs_.clear();
}

void CandumpRecorder::reconfigure(const RecordingSpec& spec) {
  const std::lock_guard lock(mutex_);
  spec_ = spec;
}

CandumpStatus CandumpRecorder::status() const {
  CandumpStatus out;
  const std::lock_guard lock(mutex_);
  out.recording = !logs_.empty();
  for (const SegmentLog& log : logs_) {
    if (log.fd.get() >= 0) out.files_open.push_back(log.path);
  }
  out.files = files_;
  out.lines = lines_;
  out.bytes = bytes_;
  out.dropped_full = dropped_full_.load(std::memory_order_relaxed);
  out.dropped_failed = dropped_failed_;
  out.last_error = last_error_;
  return out;
}

void CandumpRecorder::run() {
  for (const std::string& problem : apply_thread_policy(ThreadPolicy{"candump", 0, 19, {}}))
    log_.log(LogLevel::warning, "candump: could not get " + problem);
  std::unique_lock lock(mutex_);
  while (!quit_) {
    wake_.wait_for(lock, kPoll, [this] { return quit_; });
    write_queued(true);
  }
}

void CandumpRecorder::write_queued(bool rotate_due) {
  while (ring_.read([this](std::span<const std::uint8_t> record) { take(record); }, kBatch) == kBatch) {
  }
  const Nanos now = steady_now();
  for (SegmentLog& log : logs_) {
    flush(log);
    if (!rotate_due) continue;
    const bool old = log.fd.get() >= 0 && now - log.opened >= spec_.rotate_duration;
    if (old) close(log);
    if (log.fd.get() < 0 && now >= log.retry_at) {
      if (auto opened = open(log); !opened) fail(log, opened.error().text);
    }
  }
}

void CandumpRecorder::take(std::span<const std::uint8_t> record) {
  QueuedFrame head{};
  if (record.size() < sizeof head) return;
  std::memcpy(&head, record.data(), sizeof head);
  const auto slot = static_cast<std::uint32_t>(head.slot_and_session);
  // A frame of an earlier recording, queued as it stopped: part of none.
  if (head.slot_and_session >> 32 != session_ || slot >= logs_.size()) return;
  SegmentLog& log = logs_[slot];
  const auto frame = candump_frame_from_wire(record.subspan(sizeof head));
  if (!frame) return;  // not a SocketCAN frame: the adapter's bug, nothing to log
  if (log.fd.get() < 0) {
    ++dropped_failed_;
    return;
  }
  append_candump_line(head.utc_ns, log.segment.interface, *frame, log.pending);
  ++log.pending_lines;
  // At the limit, so a file ends with the line that takes it there (flush rotates).
  if (log.pending.size() >= kWriteAt || log.bytes_in_file + log.pending.size() >= spec_.rotate_size) flush(log);
}

void CandumpRecorder::flush(SegmentLog& log) {
  if (log.pending.empty() || log.fd.get() < 0) return;
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(log.pending.data());
  if (auto written = write_all(log.fd.get(), log.path, {bytes, log.pending.size()}); !written) {
    dropped_failed_ += log.pending_lines;
    fail(log, written.error().text);
  } else {
    lines_ += log.pending_lines;
    bytes_ += log.pending.size();
    log.bytes_in_file += log.pending.size();
  }
  log.pending.clear();
  log.pending_lines = 0;
  // Here, not only between polls: one poll may bring a file's worth.
  if (log.fd.get() >= 0 && log.bytes_in_file >= spec_.rotate_size) {
    close(log);
    if (auto opened = open(log); !opened) fail(log, opened.error().text);
  }
}

Result<void> CandumpRecorder::open(SegmentLog& log) {
  const std::int64_t utc = realtime_now_ns();
  std::string path;
  const auto create = [&] {
    path = (std::filesystem::path(spec_.directory) /
            recording_file_name(gateway_ + "-" + log.segment.name, utc, ++numbered_, ".log"))
               .string();
    return posix_call("cannot create " + path,
                      [&] { return ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640); });
  };
  auto fd = create();
  // A file of that name exists (a cosmicd restarted within the same second): the next number.
  for (int tries = 0; !fd && fd.error().code == EEXIST && tries < 1000; ++tries) fd = create();
  if (!fd) return std::move(fd).error();
  log.fd = OwnedFd(fd.value());
  log.path = path;
  log.opened = steady_now();
  log.bytes_in_file = 0;
  ++files_;
  return {};
}

void CandumpRecorder::close(SegmentLog& log) {
  const int fd = log.fd.release();
  if (fd < 0) return;
  // What was written is the file's either way; a failed sync is reported like a failed write.
  if (::fdatasync(fd) != 0) last_error_ = Error::from_errno("cannot sync " + log.path, errno).text;
  ::close(fd);
}

void CandumpRecorder::fail(SegmentLog& log, const std::string& why) {
  if (why != last_error_) log_.log(LogLevel::error, "candump: " + why);
  last_error_ = why;
  close(log);
  log.retry_at = steady_now() + kRetryEvery;
}

}  // namespace cosmic

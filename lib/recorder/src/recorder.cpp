// The recorder (cosmic/recorder.hpp): the ingress side (offer) and the control side here, the
// writer thread's loop in recorder_writer.cpp.
#include "cosmic/recorder.hpp"

#include <sys/stat.h>

#include <cstring>
#include <filesystem>

#include "cosmic/json_schema.hpp"
#include "recorder_shared.hpp"
#include "recording_file.hpp"

namespace cosmic {
namespace {

using recorder_detail::QueuedHead;

}  // namespace

Recorder::Recorder(RecordingSpec spec, std::string gateway, Logger& log)
    : spec_(std::move(spec)),
      gateway_(std::move(gateway)),
      log_(log),
      ring_(spec_.memory),
      shared_(std::make_unique<Shared>()) {
  shared_->spec = spec_;
  shared_->status.directory = spec_.directory;
  shared_->status.queue_bytes = ring_.capacity();
  thread_ = std::thread([this] { run(); });
}

Recorder::~Recorder() {
  {
    const std::lock_guard lock(shared_->mutex);
    shared_->quit = true;
  }
  shared_->wake.notify_all();
  thread_.join();
}

void Recorder::offer(ChannelId channel, std::size_t from_segment, const EventHeader& header, Nanos received_at,
                     std::span<const std::uint8_t> payload) noexcept {
  QueuedHead head{};
  head.channel = channel;
  head.segment = static_cast<std::uint32_t>(from_segment);
  head.origin = header.origin;
  head.sequence = header.sequence;
  head.created_ns = header.created_ns;
  // No clock read here: the writer puts the arrival on the UTC clock.
  head.received_ns = received_at.count();
  const std::span<const std::uint8_t> parts[] = {{reinterpret_cast<const std::uint8_t*>(&head), sizeof head}, payload};
  if (!ring_.try_write(parts)) dropped_full_.fetch_add(1, std::memory_order_relaxed);
}

namespace {

std::uint64_t fingerprint(std::initializer_list<std::string_view> parts) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (const std::string_view part : parts) {
    for (const char c : part) hash = (hash ^ static_cast<std::uint8_t>(c)) * 0x100000001b3ull;
    hash = (hash ^ 0xffu) * 0x100000001b3ull;  // "ab","c" differs from "a","bc"
  }
  return hash;
}

}  // namespace

std::optional<std::string> set_typed_encoding(RecordedChannel& channel, const ChannelType& type,
                                              TypedEncoding encoding) {
  channel.cdr.reset();
  channel.ros2msg = {};
  channel.json.reset();
  channel.json_schema.clear();
  std::string why_not;
  if (encoding == TypedEncoding::cdr) {
    // XCDR1, final, little-endian: what ROS 2's rmw writes, and what the definition reads.
    auto schema = ros2_msg_schema(type, channel.name);
    auto cdr = CdrRepresentation::make(type, DdsRepresentation::xcdr1, CdrExtensibility::final_type);
    if (schema && cdr) {
      channel.cdr = std::make_shared<const CdrRepresentation>(std::move(cdr).value());
      channel.ros2msg = std::move(schema).value();
      channel.form = fingerprint({"cdr", channel.ros2msg.name, channel.ros2msg.text});
      return std::nullopt;
    }
    why_not = !schema ? schema.error().text : cdr.error().text;
  }
  channel.json = std::make_shared<const JsonRepresentation>(type);
  channel.json_schema = json_schema(type, channel.name);
  channel.form = fingerprint({"json", channel.json_schema});
  if (why_not.empty()) return std::nullopt;
  return why_not;
}

void Recorder::set_channels(std::vector<RecordedChannel> channels) {
  auto table = std::make_shared<Shared::ChannelTable>();
  for (auto& channel : channels) {
    const ChannelId id = channel.id;
    (*table)[id] = std::make_shared<const RecordedChannel>(std::move(channel));
  }
  const std::lock_guard lock(shared_->mutex);
  shared_->channels = std::move(table);
}

void Recorder::set_segment_names(std::vector<std::string> names) {
  auto table = std::make_shared<const std::vector<std::string>>(std::move(names));
  const std::lock_guard lock(shared_->mutex);
  shared_->segments = std::move(table);
}

Result<void> Recorder::start() {
  std::error_code failed;
  std::filesystem::create_directories(spec_.directory, failed);
  if (failed) return Error{"cannot make the recording directory " + spec_.directory + ": " + failed.message()};
  if (::access(spec_.directory.c_str(), W_OK | X_OK) != 0)
    return Error::from_errno("cannot write into the recording directory " + spec_.directory, errno);
  std::uint64_t generation = 0;
  {
    const std::lock_guard lock(shared_->mutex);
    if (shared_->want_recording) return {};
    shared_->want_recording = true;
    generation = ++shared_->generation;
  }
  shared_->wake.notify_all();
  // The writer opens the first file; its verdict is this call's.
  std::unique_lock lock(shared_->mutex);
  shared_->acknowledged.wait_for(lock, std::chrono::seconds(10), [&] { return shared_->acked >= generation; });
  if (shared_->acked < generation) {
    // Taken back, so a late writer neither opens a file nobody stops nor merges this with a stop.
    shared_->want_recording = false;
    ++shared_->generation;
    lock.unlock();
    shared_->wake.notify_all();
    return Error{"the recorder's writer did not answer within 10 s"};
  }
  if (!shared_->status.recording) {
    shared_->want_recording = false;
    return Error{shared_->status.last_error};
  }
  log_.log(LogLevel::notice, "recording to " + shared_->status.file);
  return {};
}

void Recorder::stop() {
  std::uint64_t generation = 0;
  {
    const std::lock_guard lock(shared_->mutex);
    if (!shared_->want_recording) return;
    shared_->want_recording = false;
    generation = ++shared_->generation;
  }
  shared_->wake.notify_all();
  std::unique_lock lock(shared_->mutex);
  shared_->acknowledged.wait_for(lock, std::chrono::seconds(10), [&] { return shared_->acked >= generation; });
}

void Recorder::reconfigure(RecordingSpec spec) {
  spec.memory = spec_.memory;  // the queue keeps its size (its memory is the ingress threads')
  spec_ = std::move(spec);
  const std::lock_guard lock(shared_->mutex);
  shared_->spec = spec_;
  shared_->status.directory = spec_.directory;
}

RecorderStatus Recorder::status() const {
  RecorderStatus out;
  {
    const std::lock_guard lock(shared_->mutex);
    out = shared_->status;
  }
  out.dropped_full = dropped_full_.load(std::memory_order_relaxed);
  out.queued_bytes = ring_.used();
  return out;
}

}  // namespace cosmic

// One MCAP file of the recorder (recording_file.hpp).
#include "recording_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <ctime>

namespace cosmic::recorder_detail {
namespace {

std::string hex(std::uint64_t value) {
  char text[20];
  std::snprintf(text, sizeof text, "%llx", static_cast<unsigned long long>(value));
  return text;
}

// The MCAP encodings of a recorded channel's messages and of their schema (none: empty), and the
// schema's name and text.
struct RecordedForm {
  std::string_view message_encoding;
  std::string_view schema_encoding;
  std::string_view schema_name;
  std::string_view schema;
};

RecordedForm recorded_form(const RecordedChannel& channel) {
  if (channel.cdr) return {"cdr", "ros2msg", channel.ros2msg.name, channel.ros2msg.text};
  if (channel.json) return {"json", "jsonschema", channel.name, channel.json_schema};
  return {"x-cosmic-bytes", {}, {}, {}};
}

}  // namespace

Result<void> write_all(int fd, const std::string& path, std::span<const std::uint8_t> bytes) {
  while (!bytes.empty()) {
    auto written = posix_call("cannot write " + path, [&] { return ::write(fd, bytes.data(), bytes.size()); });
    if (!written) return std::move(written).error();
    bytes = bytes.subspan(static_cast<std::size_t>(written.value()));
  }
  return {};
}

std::string recording_file_name(const std::string& stem, std::int64_t utc_ns, std::uint64_t n,
                                std::string_view extension) {
  const std::time_t seconds = static_cast<std::time_t>(utc_ns / 1'000'000'000);
  std::tm parts{};
  ::gmtime_r(&seconds, &parts);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &parts);
  return stem + "-" + stamp + "-" + std::to_string(n) + std::string(extension);
}

Result<std::unique_ptr<RecordingFile>> RecordingFile::create(const std::string& path, const RecordingSpec& spec,
                                                             const std::string& gateway, std::int64_t opened_ns) {
  auto fd = posix_call("cannot create " + path,
                       [&] { return ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640); });
  if (!fd) return std::move(fd).error();
  OwnedFd owned(fd.value());
  McapWriterOptions options;
  options.profile = "x-cosmic";
  options.library = "cosmic-gateway";
  options.compression = spec.compression == RecordCompression::zstd ? McapCompression::zstd : McapCompression::none;
  options.chunk_size = spec.chunk_size;
  // Compressing is most of the writer's work per event: zstd's level 1 does it in two thirds of the
  // time of its default 3, and as well on recorded events (cosmic_recorder_bench: 7.7:1 against 7.1:1).
  options.zstd_level = 1;
  const int raw = owned.get();
  auto writer = McapWriter::open(
      options, [raw, path](std::span<const std::uint8_t> bytes) { return write_all(raw, path, bytes); });
  // A file that cannot even take its header is not left behind (a full disk would gather one per retry).
  const auto discard = [&path](Error error) {
    ::unlink(path.c_str());
    return error;
  };
  if (!writer) return discard(std::move(writer).error());
  std::unique_ptr<RecordingFile> file(new RecordingFile(path, std::move(owned), opened_ns, std::move(writer).value()));
  const McapMap about{{"gateway", gateway}, {"opened_utc_ns", std::to_string(opened_ns)}};
  if (auto written = file->writer_.add_metadata("cosmic", about); !written) return discard(std::move(written).error());
  return file;
}

RecordingFile::RecordingFile(std::string path, OwnedFd fd, std::int64_t opened_ns, McapWriter writer)
    : path_(std::move(path)), fd_(std::move(fd)), opened_ns_(opened_ns), writer_(std::move(writer)) {}

RecordingFile::~RecordingFile() = default;

Result<std::uint16_t> RecordingFile::channel_id(const RecordedChannel& channel, const TakenEvent& event) {
  const StreamKey key{channel.id, event.segment_slot, event.origin, channel.form};
  if (const auto it = channels_.find(key); it != channels_.end()) return it->second;
  const RecordedForm form = recorded_form(channel);
  std::uint16_t schema = 0;
  if (!form.schema_encoding.empty()) {
    if (const auto it = schemas_.find({channel.id, channel.form}); it != schemas_.end()) {
      schema = it->second;
    } else {
      const auto* text = reinterpret_cast<const std::uint8_t*>(form.schema.data());
      auto added = writer_.add_schema(form.schema_name, form.schema_encoding, {text, form.schema.size()});
      if (!added) return std::move(added).error();
      schema = schemas_[{channel.id, channel.form}] = added.value();
    }
  }
  McapMap metadata = channel.metadata;
  metadata["segment"] = event.segment != nullptr ? *event.segment : std::to_string(event.segment_slot);
  metadata["origin"] = hex(event.origin);
  auto added = writer_.add_channel(schema, channel.name, form.message_encoding, metadata);
  if (!added) return std::move(added).error();
  channels_.emplace(key, added.value());
  return added.value();
}

Result<bool> RecordingFile::write(const RecordedChannel& channel, const TakenEvent& event) {
  // Declaring writes nothing to the file yet (the records go into the open chunk): a refusal here
  // is this event's, not the file's.
  const auto id = channel_id(channel, event);
  if (!id) return false;
  auto written =
      writer_.write_message(id.value(), event.sequence, static_cast<std::uint64_t>(event.arrival_ns),
                            static_cast<std::uint64_t>(std::max<std::int64_t>(event.created_ns, 0)), event.contents);
  if (!written) return std::move(written).error();
  return true;
}

Result<void> RecordingFile::finish(const McapMap& closing) {
  auto finished = writer_.add_metadata("cosmic.closing", closing);
  if (finished) finished = writer_.finish();
  if (const int fd = fd_.release(); fd >= 0) {
    // What was written is the file's either way; a failed fsync is as bad as a failed write.
    const bool synced = ::fdatasync(fd) == 0;
    const int err = errno;
    ::close(fd);
    if (finished && !synced) return Error::from_errno("cannot sync " + path_, err);
  }
  return finished;
}

}  // namespace cosmic::recorder_detail

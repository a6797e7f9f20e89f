// One MCAP file of the recorder (cosmic/recorder.hpp): the file descriptor, the MCAP writer over
// it, and the MCAP channels and schemas declared in it so far. Internal to the recorder; its writer
// thread only.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>

#include "cosmic/mcap_writer.hpp"
#include "cosmic/model.hpp"
#include "cosmic/posix_call.hpp"
#include "cosmic/recorder.hpp"
#include "cosmic/units.hpp"

namespace cosmic::recorder_detail {

// What the recorder knows of one event taken from its queue.
struct TakenEvent {
  ChannelId channel = kNoChannel;
  std::string segment;  // the source segment's name
  std::uint64_t origin = 0;
  std::uint32_t sequence = 0;
  std::int64_t created_ns = 0;             // on the origin's clock
  std::int64_t arrival_ns = 0;             // UTC, this host's clock
  std::span<const std::uint8_t> contents;  // JSON for a typed channel, else the event's bytes
};

class RecordingFile {
 public:
  // Creates `path` (never an existing file) and writes the MCAP header and a metadata record
  // naming the gateway.
  static Result<std::unique_ptr<RecordingFile>> create(const std::string& path, const RecordingSpec& spec,
                                                       const std::string& gateway, std::int64_t opened_ns);
  ~RecordingFile();
  RecordingFile(const RecordingFile&) = delete;
  RecordingFile& operator=(const RecordingFile&) = delete;

  // Appends one event of `channel` (declaring its schema and MCAP channel on first use): true when
  // written, false when this file cannot take the event (no MCAP channel id is left). An error
  // means the file can take no more: finish() it and open another.
  Result<bool> write(const RecordedChannel& channel, const TakenEvent& event);
  Result<void> flush_chunk() { return writer_.flush_chunk(); }
  // Ends the file (summary, footer) and closes it; what was written stays either way.
  Result<void> finish();

  const std::string& path() const { return path_; }
  std::int64_t opened_ns() const { return opened_ns_; }
  const McapWriter& writer() const { return writer_; }

 private:
  RecordingFile(std::string path, OwnedFd fd, std::int64_t opened_ns, McapWriter writer);
  Result<std::uint16_t> channel_id(const RecordedChannel& channel, const TakenEvent& event);

  std::string path_;
  OwnedFd fd_;
  std::int64_t opened_ns_;
  McapWriter writer_;
  std::map<ChannelId, std::uint16_t> schemas_;
  std::map<std::tuple<ChannelId, std::string, std::uint64_t>, std::uint16_t> channels_;
};

// "STEM-YYYYMMDD-HHMMSS-N.EXT" for a file opened at `utc_ns`, the Nth of its recorder (the MCAP
// recorder's stem is the gateway's name, the CAN logs' GATEWAY-SEGMENT).
std::string recording_file_name(const std::string& stem, std::int64_t utc_ns, std::uint64_t n,
                                std::string_view extension);

// Everything of `bytes` written to `fd`, however many calls that takes.
Result<void> write_all(int fd, const std::string& path, std::span<const std::uint8_t> bytes);

}  // namespace cosmic::recorder_detail

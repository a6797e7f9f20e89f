// One MCAP file of the recorder (cosmic/recorder.hpp): the file descriptor, the MCAP writer over
// it, and the MCAP channels and schemas declared in it so far. Internal to the recorder; its writer
// thread only.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "cosmic/mcap_writer.hpp"
#include "cosmic/model.hpp"
#include "cosmic/posix_call.hpp"
#include "cosmic/recorder.hpp"
#include "cosmic/units.hpp"

namespace cosmic::recorder_detail {

// What the recorder knows of one event taken from its queue.
struct TakenEvent {
  ChannelId channel = kNoChannel;
  std::uint32_t segment_slot = 0;        // the router's slot of the source segment
  const std::string* segment = nullptr;  // its name (the recorder's table of slot names)
  std::uint64_t origin = 0;
  std::uint32_t sequence = 0;
  std::int64_t created_ns = 0;             // on the origin's clock
  std::int64_t arrival_ns = 0;             // UTC, this host's clock
  std::span<const std::uint8_t> contents;  // CDR or JSON for a typed channel, else the event's bytes
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
  // The router's segment slots were renamed (a reload): later events get MCAP channels naming the
  // new segments; those declared so far stay in the file.
  void forget_streams() { channels_.clear(); }
  // Ends the file (summary, footer) and closes it; what was written stays either way. `closing`
  // goes in first as the Metadata record "cosmic.closing" (what was dropped while this file was
  // open, for `cosmicctl record info`).
  Result<void> finish(const McapMap& closing);

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
  // By (channel, its form, source slot, origin): found per event without building a string.
  struct StreamKey {
    ChannelId channel;
    std::uint32_t slot;
    std::uint64_t origin;
    std::uint64_t form;
    friend bool operator==(const StreamKey&, const StreamKey&) = default;
  };
  struct StreamKeyHash {
    std::size_t operator()(const StreamKey& k) const noexcept {
      return std::hash<std::uint64_t>{}((k.origin ^ k.form) * 0x9e3779b97f4a7c15ull ^
                                        (std::uint64_t{k.channel} << 32 | k.slot));
    }
  };
  std::map<std::pair<ChannelId, std::uint64_t>, std::uint16_t> schemas_;  // by (channel, form)
  std::unordered_map<StreamKey, std::uint16_t, StreamKeyHash> channels_;
};

// "STEM-YYYYMMDD-HHMMSS-N.EXT" for a file opened at `utc_ns`, the Nth of its recorder (the MCAP
// recorder's stem is the gateway's name, the CAN logs' GATEWAY-SEGMENT).
std::string recording_file_name(const std::string& stem, std::int64_t utc_ns, std::uint64_t n,
                                std::string_view extension);

// Everything of `bytes` written to `fd`, however many calls that takes.
Result<void> write_all(int fd, const std::string& path, std::span<const std::uint8_t> bytes);

}  // namespace cosmic::recorder_detail

// The recorder (issue 37, docs/recording.md): what crossed the gateway, written to MCAP files as it
// arrives, without ever delaying forwarding.
//
// The router hands it each admitted event of a selected channel (cosmic/record_hook.hpp); offer()
// copies the event with its arrival time, creation time, source segment and origin into a bounded
// many-to-one queue (cosmic/record_ring.hpp, `recording.memory` bytes) or counts it dropped when
// the queue is full. One writer thread ("record", nice 19: below the NRT lanes) takes the events,
// turns a typed channel's compact events into CDR (with the type's ROS 2 message definition) or
// JSON (with its JSON Schema), as recording.typed_encoding and the type allow, and writes them
// into chunked, compressed MCAP files in `recording.directory`, named
// GATEWAY-YYYYMMDD-HHMMSS-N.mcap (UTC), a new file when one reaches `rotate.size` or has been
// written for `rotate.duration`. The open chunk is closed at least once a second, so a crash loses
// at most that much of what was queued. A write that fails (a full disk) closes the file as it is
// (readable up to its last whole chunk), the events of the chunk it could not write and those
// meanwhile count as dropped (not written), and a new file is tried every few seconds. stop()
// writes every event queued before it.
//
// MCAP channels: one per cosmic channel, source segment and origin (the topic is the channel's
// name for all of them; their metadata names the segment and origin), because a message record
// has no room for either.
//
// Threads: offer() on the router's ingress threads (never blocks, allocates or does I/O); every
// other call on the control thread; the writer thread is the recorder's own. The owner keeps the
// recorder alive while the router can call offer().
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/cdr_representation.hpp"
#include "cosmic/json_representation.hpp"
#include "cosmic/log.hpp"
#include "cosmic/mcap_records.hpp"
#include "cosmic/model.hpp"
#include "cosmic/record_hook.hpp"
#include "cosmic/record_ring.hpp"
#include "cosmic/result.hpp"
#include "cosmic/ros2_msg_schema.hpp"

namespace cosmic {

// What the recorder needs to know of a channel it records (made by the owner when channels are
// bound, shared read-only with the writer thread).
struct RecordedChannel {
  ChannelId id = kNoChannel;
  std::string name;
  // A typed channel: its events as JSON, and the JSON Schema of that; null/empty for an untyped one,
  // whose events are recorded as the bytes they came in (message encoding "x-cosmic-bytes").
  std::shared_ptr<const JsonRepresentation> json{};
  std::string json_schema{};
  // A typed channel recorded as CDR (recording.typed_encoding: cdr), which takes precedence over
  // json: its events as the XCDR1 samples ROS 2 writes (message encoding "cdr") and the ROS 2
  // message definition that reads them (schema encoding "ros2msg").
  std::shared_ptr<const CdrRepresentation> cdr{};
  Ros2MsgSchema ros2msg{};
  McapMap metadata{};  // the channel's contract: subject, class, period, payload, ...
  // How its events are written (encoding and schema), as a fingerprint: a channel whose type a
  // replacement changed (same id) gets a schema and MCAP channels of its own in the open file, so
  // every message reads with the schema it was written for. 0: its bytes.
  std::uint64_t form = 0;
};

// Sets how the typed channel `channel` (its id and name set) records events of `type`: as CDR
// when `encoding` asks for it and the type has a CDR form and a ROS 2 message definition, else as
// JSON. Returns why CDR was asked for and not used, for the caller to say once; nullopt otherwise.
// Builds the representations and schema text: once per channel when the channel table is built.
std::optional<std::string> set_typed_encoding(RecordedChannel& channel, const ChannelType& type,
                                              TypedEncoding encoding);

struct RecorderStatus {
  bool recording = false;
  std::string directory;
  std::string file;                   // being written; empty when none is open
  std::uint64_t files = 0;            // files finished since the recorder was made
  std::uint64_t messages = 0;         // written, in all files
  std::uint64_t bytes = 0;            // written, in all files
  std::uint64_t uncompressed = 0;     // chunk records before compression, in all files
  std::uint64_t compressed = 0;       // and after
  std::uint64_t dropped_full = 0;     // offered while the queue had no room (or too long for it)
  std::uint64_t dropped_failed = 0;   // taken while no file could be written
  std::uint64_t dropped_invalid = 0;  // a typed event that did not convert, or too many MCAP channels
  std::size_t queue_bytes = 0;        // the queue's size
  std::size_t queued_bytes = 0;       // what waits in it now
  std::string last_error;             // the last write or open failure; empty when none
};

class Recorder final : public RecordHook {
 public:
  // Starts the writer thread; recording begins with start().
  Recorder(RecordingSpec spec, std::string gateway, Logger& log);
  ~Recorder() override;
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Ingress threads: queue the event, or count it dropped.
  void offer(ChannelId channel, std::size_t from_segment, const EventHeader& header, Nanos received_at,
             std::span<const std::uint8_t> payload) noexcept override;

  // Control thread. The channels it may see, and the names of the router's segment slots.
  void set_channels(std::vector<RecordedChannel> channels);
  void set_segment_names(std::vector<std::string> names);
  // Opens the first file (the directory is made if missing); an error when that fails.
  Result<void> start();
  // Writes what is queued, finishes the file and waits for that (at most a few seconds).
  void stop();
  // A reload's new section: directory, compression, chunking and rotation apply from the next file;
  // the selection is the owner's (Router::select_recorded). The queue keeps its size.
  void reconfigure(RecordingSpec spec);
  RecorderStatus status() const;
  const RecordingSpec& spec() const { return spec_; }

 private:
  struct Shared;
  class Writer;
  void run();

  RecordingSpec spec_;  // control thread's copy
  std::string gateway_;
  Logger& log_;
  RecordRing ring_;
  std::atomic<std::uint64_t> dropped_full_{0};
  std::unique_ptr<Shared> shared_;
  std::thread thread_;
};

}  // namespace cosmic

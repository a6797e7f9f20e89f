// What the recorder's control side and its writer thread share (cosmic/recorder.hpp), and the
// head of each event in the queue. Internal to the recorder.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cosmic/recorder.hpp"

namespace cosmic {

namespace recorder_detail {

// Copied into the queue in front of the event's bytes (plain bytes, this process only).
struct QueuedHead {
  ChannelId channel;
  std::uint32_t segment;  // the router's slot of the source segment
  std::uint64_t origin;
  std::uint32_t sequence;
  std::uint32_t reserved;  // keeps the layout free of padding
  std::int64_t created_ns;
  std::int64_t received_ns;  // CLOCK_MONOTONIC (the writer turns it into UTC, one clock reading a batch)
};

}  // namespace recorder_detail

struct Recorder::Shared {
  using ChannelTable = std::map<ChannelId, std::shared_ptr<const RecordedChannel>>;

  std::mutex mutex;
  std::condition_variable wake;          // control -> writer: a request, or quit
  std::condition_variable acknowledged;  // writer -> control: `acked` reached a generation
  bool quit = false;
  bool want_recording = false;
  std::uint64_t generation = 0;  // bumped by start() and stop()
  std::uint64_t acked = 0;       // the last generation the writer acted on
  RecordingSpec spec;            // what the next file follows
  std::shared_ptr<const ChannelTable> channels = std::make_shared<const ChannelTable>();
  std::shared_ptr<const std::vector<std::string>> segments = std::make_shared<const std::vector<std::string>>();
  RecorderStatus status;  // kept by the writer
};

}  // namespace cosmic

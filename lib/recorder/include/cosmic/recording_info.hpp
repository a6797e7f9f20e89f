// What a recording holds (issue 37, `cosmicctl record info FILE`): per MCAP channel (a cosmic
// channel from one source segment and origin) its messages, bytes, time span, rate, largest gap
// between two messages and the sequence numbers missing; for the file its span, chunks,
// compression, the drops the recorder noted when it closed the file, and whether the file was cut
// short (a crash: everything up to the last complete chunk is counted).
//
// Pure: reads the caller's bytes (a mapped file), no I/O. Any thread.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cosmic/mcap_records.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

struct RecordedStream {
  std::string topic;     // the channel's name
  std::string segment;   // where its events came from ("" when the channel does not say)
  std::string origin;    // hex, as the channel's metadata says
  std::string encoding;  // "json", "x-cosmic-bytes", ...
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;     // of the messages' contents
  std::uint64_t first_ns = 0;  // log times (arrival, UTC)
  std::uint64_t last_ns = 0;
  std::uint64_t largest_gap_ns = 0;  // between two successive messages
  std::uint64_t missing = 0;         // sequence numbers skipped (a number lower than the last is not counted)
  // Messages per second over the stream's span; 0 with fewer than two messages.
  double rate_hz() const;
};

struct RecordingInfo {
  std::string profile;
  std::string library;
  std::string gateway;  // from the "cosmic" metadata record, when there is one
  bool whole = false;   // a Footer and summary: the file was finished
  std::string truncation;
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  std::uint64_t start_ns = 0;
  std::uint64_t end_ns = 0;
  std::uint64_t compressed_bytes = 0;  // of the chunks (summary only)
  std::uint64_t uncompressed_bytes = 0;
  McapMap closing;                      // "cosmic.closing": dropped_queue_full, dropped_not_written, dropped_invalid
  std::vector<RecordedStream> streams;  // in the order of the channels' first records
};

// Reads `file` whole (one decompressed chunk at a time). An error for a file that is not MCAP or
// is damaged (not merely cut short).
Result<RecordingInfo> recording_info(std::span<const std::uint8_t> file);

}  // namespace cosmic

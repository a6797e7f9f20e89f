// Reads MCAP files (https://mcap.dev/spec) from bytes the caller holds: the whole file record by
// record (scan_mcap, read_mcap), or its summary alone from the end of the file (read_mcap_summary),
// for `cosmicctl record info` on big files. No file I/O: the caller maps or reads the file.
//
// A file cut short (a crash while recording: no Footer, a record cut in the middle) is not an
// error: the readers give everything up to its last complete record (a chunk only when it is
// whole) with `truncated` set and a sentence saying where and how it ends. A file that is damaged
// instead is an error whose text names the byte offset ("mcap offset 1234: ..."): bad magic, a
// record running past its section in a file that has its Footer, a chunk that does not decompress
// or fails its CRC, a message on a channel never declared, a schema or channel redefined
// differently. Lengths are checked before use and limited (McapReadLimits), so no input makes the
// readers read out of bounds or allocate without bound.
//
// Compressions read: zstd, lz4 (LZ4 frames, as other MCAP writers produce) and none.
//
// Threads: pure functions; any thread. Ownership: McapFile owns copies; a McapMessageView handed
// to a scan callback points into a buffer valid only during the call.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosmic/mcap_records.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

struct McapReadLimits {
  // A chunk may decompress to at most this many bytes ...
  std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;
  // ... and to at most max_ratio times its compressed size (a few KiB of zeros must not claim a
  // gigabyte), though always to min_ratio_floor bytes.
  std::uint64_t max_ratio = 1000;
  std::uint64_t min_ratio_floor = std::uint64_t{1} << 20;
  // The summary section read by read_mcap_summary, at most.
  std::uint64_t max_summary_bytes = std::uint64_t{1} << 30;
};

// What the summary section says (present when the Footer names one).
struct McapSummary {
  McapHeader header;
  McapFooter footer;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::optional<McapStatistics> statistics;
  std::vector<McapChunkIndex> chunk_indexes;
  std::vector<McapMetadataIndex> metadata_indexes;
  std::vector<McapSummaryOffset> summary_offsets;
};

// What a scan found besides the messages.
struct McapScan {
  McapHeader header;
  std::vector<McapSchema> schemas;    // in the order of their first record
  std::vector<McapChannel> channels;  // in the order of their first record
  std::vector<McapMetadata> metadata;
  std::uint64_t message_count = 0;
  std::uint64_t chunk_count = 0;
  std::optional<McapSummary> summary;  // when the file is whole and has one
  bool truncated = false;
  std::string truncation;            // where and how a truncated file ends, for a person
  std::uint64_t complete_bytes = 0;  // the file's bytes up to the end of its last complete record
};

// A message with its bytes copied out (read_mcap).
struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::vector<std::uint8_t> data;
  friend bool operator==(const McapMessage&, const McapMessage&) = default;
};

struct McapFile : McapScan {
  std::vector<McapMessage> messages;  // in file order
};

// Called for each message in file order, with its channel (declared earlier in the file). An
// error returned stops the scan and is its result.
using McapMessageCallback = std::function<Result<void>(const McapMessageView&, const McapChannel&)>;

// Walks the whole file; memory: one decompressed chunk at a time plus schemas and channels.
Result<McapScan> scan_mcap(std::span<const std::uint8_t> file, const McapMessageCallback& on_message,
                           const McapReadLimits& limits = {});
// scan_mcap keeping a copy of every message.
Result<McapFile> read_mcap(std::span<const std::uint8_t> file, const McapReadLimits& limits = {});

// Fills `out` with the file's bytes at `offset` (exactly out.size() of them, or an error).
using McapReadAt = std::function<Result<void>(std::uint64_t offset, std::span<std::uint8_t> out)>;

// The summary alone: reads the leading magic and Header, the Footer and closing magic, then the
// summary section (checking its CRC when the Footer has one), never the data section. nullopt
// when the Footer says the file has no summary; an error when there is no Footer (a truncated
// file: scan it instead) or what it points at is damaged.
Result<std::optional<McapSummary>> read_mcap_summary(std::uint64_t file_size, const McapReadAt& read_at,
                                                     const McapReadLimits& limits = {});
Result<std::optional<McapSummary>> read_mcap_summary(std::span<const std::uint8_t> file,
                                                     const McapReadLimits& limits = {});

}  // namespace cosmic

// The records of an MCAP file (https://mcap.dev/spec, major version 0) as plain values, and their
// byte form: `append_mcap_record` writes one whole record (opcode, u64 length, content), the
// `parse_mcap_*` functions read one record's content. McapWriter and the readers are built on
// these; a tool that wants to look at single records (the recorder's `record info`, tests) can too.
//
// Layout facts the code relies on: every integer little endian; a String is a u32 byte length and
// the bytes; a Map is a u32 byte length and its entries; a record's content may grow new fields at
// its end in later versions of the format, so parsers ignore bytes after the fields they know.
//
// Ownership: every struct owns its bytes, except McapMessageView and McapChunkView, which point
// into a buffer the caller keeps alive. Threads: plain values and pure functions; any thread.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosmic/result.hpp"

namespace cosmic {

// Opening and closing magic; byte 5 ('0') is the format's major version.
inline constexpr std::array<std::uint8_t, 8> kMcapMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
// Opcode byte and u64 content length in front of every record.
inline constexpr std::size_t kMcapRecordPrefix = 9;
// The Footer's content (summary_start, summary_offset_start, summary_crc): never extended.
inline constexpr std::size_t kMcapFooterContent = 20;
// What a reader of the summary reads first: the Footer record and the closing magic.
inline constexpr std::size_t kMcapFooterTail = kMcapRecordPrefix + kMcapFooterContent + kMcapMagic.size();

enum class McapOpcode : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

// Channel metadata and Metadata records. Sorted, so equal maps always give equal bytes.
using McapMap = std::map<std::string, std::string>;

struct McapHeader {
  std::string profile;  // e.g. "" or "ros2"; cosmicd writes "x-cosmic"
  std::string library;  // free text naming the writer
  friend bool operator==(const McapHeader&, const McapHeader&) = default;
};

struct McapFooter {
  std::uint64_t summary_start = 0;         // 0: no summary section
  std::uint64_t summary_offset_start = 0;  // 0: no Summary Offset records
  std::uint32_t summary_crc = 0;           // 0: not computed
  friend bool operator==(const McapFooter&, const McapFooter&) = default;
};

struct McapSchema {
  std::uint16_t id = 0;  // never 0 (0 on a channel means "no schema")
  std::string name;      // e.g. "cosmic_msgs/msg/Distance"
  std::string encoding;  // "ros2msg", "omgidl", "jsonschema", ...
  std::vector<std::uint8_t> data;
  friend bool operator==(const McapSchema&, const McapSchema&) = default;
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: the messages have no schema
  std::string topic;
  std::string message_encoding;  // "cdr", "json", ...
  McapMap metadata;
  friend bool operator==(const McapChannel&, const McapChannel&) = default;
};

// A Message record; `data` points into the record's buffer.
struct McapMessageView {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns, when it was recorded
  std::uint64_t publish_time = 0;  // ns, when it was published
  std::span<const std::uint8_t> data;
};

// A Chunk record; `records` points into the file's buffer and is still compressed.
struct McapChunkView {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not computed
  std::string compression;             // "zstd", "lz4" or "" (none)
  std::span<const std::uint8_t> records;
};

// Where each message of one channel sits in a chunk's uncompressed records.
struct McapMessageIndex {
  std::uint16_t channel_id = 0;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> entries;  // (log_time, offset in the records)
  friend bool operator==(const McapMessageIndex&, const McapMessageIndex&) = default;
};

struct McapChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;                          // from the start of the file
  std::uint64_t chunk_length = 0;                                // the whole Chunk record
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;  // channel -> its Message Index record
  std::uint64_t message_index_length = 0;                        // all Message Index records of the chunk
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
  friend bool operator==(const McapChunkIndex&, const McapChunkIndex&) = default;
};

struct McapStatistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;  // 0 when there are no messages
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
  friend bool operator==(const McapStatistics&, const McapStatistics&) = default;
};

struct McapMetadata {
  std::string name;
  McapMap metadata;
  friend bool operator==(const McapMetadata&, const McapMetadata&) = default;
};

struct McapMetadataIndex {
  std::uint64_t offset = 0;  // of the Metadata record, from the start of the file
  std::uint64_t length = 0;  // the whole record
  std::string name;
  friend bool operator==(const McapMetadataIndex&, const McapMetadataIndex&) = default;
};

struct McapSummaryOffset {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
  friend bool operator==(const McapSummaryOffset&, const McapSummaryOffset&) = default;
};

struct McapDataEnd {
  std::uint32_t data_section_crc = 0;  // 0: not computed
};

// zlib's CRC-32 (the one MCAP uses), continuing from `crc` (0 to start).
std::uint32_t mcap_crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0) noexcept;

// One whole record appended to `out`. A Chunk's records are given already compressed.
void append_mcap_record(std::vector<std::uint8_t>& out, const McapHeader& header);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapFooter& footer);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapSchema& schema);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapChannel& channel);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapMessageView& message);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapChunkView& chunk);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapMessageIndex& index);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapChunkIndex& index);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapStatistics& statistics);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapMetadata& metadata);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapMetadataIndex& index);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapSummaryOffset& offset);
void append_mcap_record(std::vector<std::uint8_t>& out, const McapDataEnd& data_end);

// One record's content (without opcode and length). Errors name the record and the field that does
// not fit; the readers add the offset.
Result<McapHeader> parse_mcap_header(std::span<const std::uint8_t> content);
Result<McapFooter> parse_mcap_footer(std::span<const std::uint8_t> content);
Result<McapSchema> parse_mcap_schema(std::span<const std::uint8_t> content);
Result<McapChannel> parse_mcap_channel(std::span<const std::uint8_t> content);
Result<McapMessageView> parse_mcap_message(std::span<const std::uint8_t> content);
Result<McapChunkView> parse_mcap_chunk(std::span<const std::uint8_t> content);
Result<McapMessageIndex> parse_mcap_message_index(std::span<const std::uint8_t> content);
Result<McapChunkIndex> parse_mcap_chunk_index(std::span<const std::uint8_t> content);
Result<McapStatistics> parse_mcap_statistics(std::span<const std::uint8_t> content);
Result<McapMetadata> parse_mcap_metadata(std::span<const std::uint8_t> content);
Result<McapMetadataIndex> parse_mcap_metadata_index(std::span<const std::uint8_t> content);
Result<McapSummaryOffset> parse_mcap_summary_offset(std::span<const std::uint8_t> content);
Result<McapDataEnd> parse_mcap_data_end(std::span<const std::uint8_t> content);

// A record found in a buffer: its opcode, where it starts (offset of the opcode byte) and its content.
struct McapRecordView {
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0;
  std::span<const std::uint8_t> content;
  // The whole record's length, prefix included.
  std::uint64_t length() const noexcept { return kMcapRecordPrefix + content.size(); }
};

// The record at `at` in `bytes`, or why there is none: `incomplete` when the bytes end before the
// record does (its prefix or its content), with `needed` = the bytes the record would end at.
struct McapRecordAt {
  bool incomplete = false;
  std::uint64_t needed = 0;
  McapRecordView record;
};
McapRecordAt mcap_record_at(std::span<const std::uint8_t> bytes, std::uint64_t at) noexcept;

// "header", "chunk", ... or "unknown (0xNN)", for error texts.
std::string mcap_opcode_name(std::uint8_t opcode);

}  // namespace cosmic

// Writes one MCAP file (https://mcap.dev/spec) to a byte sink the caller owns: the recorder keeps
// the file, its rotation and its thread; this class only decides the bytes.
//
// Layout: magic, Header, then the data section made of Chunks, each followed by its Message Index
// records; a Schema and a Channel record go into the chunk where the channel's first message goes,
// so every chunk can be read with what precedes it. A chunk is closed (compressed, given to the
// sink whole, chunk and indexes in one call) once its records reach `chunk_size`, on flush_chunk()
// and on finish(). Metadata records go between chunks. finish() writes Data End (with the CRC of
// everything before it), the summary (Schemas, Channels, Statistics, Chunk Indexes, Metadata
// Indexes), a Summary Offset per group, the Footer and the closing magic. A file cut short
// anywhere keeps every chunk the sink had completely received.
//
// Memory: the open chunk (about chunk_size plus one message, and as much again compressed), its
// message index (24 bytes a message, twice while the chunk closes), the channels and schemas, and
// per chunk written one Chunk Index (kept for the summary). The buffers are kept from chunk to
// chunk, so a recording in its stride allocates nothing per message.
//
// Errors: a call that cannot go on returns an Error; after the sink fails the writer refuses every
// further call (what the file holds is then unknown), the recorder drops the file or starts a new
// one. Never throws (short of std::bad_alloc), never prints.
//
// Threads: one thread at a time (the recorder's); the sink is called on that thread.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/mcap_records.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

namespace mcap_detail {
class ZstdCompressor;
}

enum class McapCompression { none, zstd };

struct McapWriterOptions {
  std::string profile = "x-cosmic";
  std::string library = "cosmic-gateway";
  McapCompression compression = McapCompression::zstd;
  std::uint64_t chunk_size = 1 << 20;  // uncompressed bytes of records per chunk, at least
  int zstd_level = 3;                  // libzstd's levels: 1 (fast) .. 19; 3 is zstd's default
};

// Receives the file's bytes in order; each call is a whole unit (the header, a chunk with its
// indexes, a metadata record, the summary to the end). The span is valid only during the call.
using McapSink = std::function<Result<void>(std::span<const std::uint8_t>)>;

class McapWriter {
 public:
  // Writes the magic and the Header to `sink`.
  static Result<McapWriter> open(McapWriterOptions options, McapSink sink);

  McapWriter(McapWriter&&) noexcept;
  McapWriter& operator=(McapWriter&&) noexcept;
  ~McapWriter();

  // Registers a schema (written before the first message of a channel using it); its id, from 1.
  Result<std::uint16_t> add_schema(std::string_view name, std::string_view encoding,
                                   std::span<const std::uint8_t> data);
  // Registers a channel; `schema_id` 0 for messages without a schema. Its id, from 1.
  Result<std::uint16_t> add_channel(std::uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                                    const McapMap& metadata = {});
  // Appends one message to the open chunk; the chunk goes to the sink when it reaches chunk_size.
  Result<void> write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                             std::uint64_t publish_time_ns, std::span<const std::uint8_t> data);
  // A Metadata record (e.g. the gateway's configuration), written to the sink at once.
  Result<void> add_metadata(std::string_view name, const McapMap& metadata);
  // Closes the open chunk now (bounds how much a crash can lose, and how late a reader sees it).
  Result<void> flush_chunk();
  // Closes the open chunk and ends the file. Afterwards every call is refused.
  Result<void> finish();

  std::uint64_t bytes_written() const noexcept { return offset_; }
  // Messages taken by write_message, the open chunk's included.
  std::uint64_t message_count() const noexcept { return statistics_.message_count; }
  // Messages in the open chunk: not yet given to the sink. After a failed flush (or finish) these
  // never reach the file: the caller counts them lost, not written.
  std::uint64_t chunk_message_count() const noexcept { return chunk_entries_.size(); }
  // The chunks' records before and after compression (their ratio is the compression ratio).
  std::uint64_t uncompressed_bytes() const noexcept { return uncompressed_bytes_; }
  std::uint64_t compressed_bytes() const noexcept { return compressed_bytes_; }

 private:
  McapWriter(McapWriterOptions options, McapSink sink);
  Result<void> emit(std::span<const std::uint8_t> bytes);
  Result<void> usable() const;
  void declare_channel_in_chunk(std::uint16_t channel_id);
  Result<void> close_chunk();
  std::vector<std::uint8_t> build_summary(std::uint64_t summary_start) const;

  McapWriterOptions options_;
  McapSink sink_;
  std::unique_ptr<mcap_detail::ZstdCompressor> zstd_;

  std::uint64_t offset_ = 0;    // bytes given to the sink
  std::uint32_t data_crc_ = 0;  // CRC of those bytes, up to Data End
  bool failed_ = false;         // the sink failed: the file is in an unknown state
  bool finished_ = false;

  std::vector<McapSchema> schemas_;    // id = index + 1
  std::vector<McapChannel> channels_;  // id = index + 1
  std::vector<bool> schema_written_;
  std::vector<bool> channel_written_;

  // One message of the open chunk, for its channel's Message Index record.
  struct ChunkEntry {
    std::uint64_t log_time = 0;
    std::uint64_t offset = 0;  // in the chunk's uncompressed records
    std::uint16_t channel_id = 0;
  };
  void append_message_indexes(McapChunkIndex& index);

  // The open chunk: its uncompressed records, message times and index entries in written order.
  std::vector<std::uint8_t> chunk_records_;
  std::vector<ChunkEntry> chunk_entries_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::vector<std::uint32_t> chunk_channel_messages_;  // by channel id - 1: its messages in the chunk
  std::vector<std::uint16_t> chunk_channels_;          // the channels with messages in the chunk
  // Reused while a chunk closes: the compressed records (kept at zstd's bound), the entries grouped
  // by channel, the Chunk record with its Message Indexes.
  std::vector<std::uint8_t> compressed_;
  std::vector<ChunkEntry> grouped_entries_;
  std::vector<std::uint8_t> chunk_out_;

  std::vector<McapChunkIndex> chunk_index_records_;
  std::vector<McapMetadataIndex> metadata_indexes_;
  McapStatistics statistics_;                    // its per-channel counts filled in by the summary
  std::vector<std::uint64_t> channel_messages_;  // by channel id - 1: its messages in the file
  std::uint64_t uncompressed_bytes_ = 0;
  std::uint64_t compressed_bytes_ = 0;
};

}  // namespace cosmic

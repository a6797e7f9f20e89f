// McapWriter (cosmic/mcap_writer.hpp): chunks built in memory and handed to the sink whole, the
// summary built from what the writer kept while writing.
#include "cosmic/mcap_writer.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#include "mcap_bytes.hpp"
#include "mcap_compression.hpp"

namespace cosmic {

namespace {

constexpr std::size_t kMaxIds = std::numeric_limits<std::uint16_t>::max();

// Widens [start, end] to take in `t`; `first` when the range is still empty.
void widen(std::uint64_t& start, std::uint64_t& end, std::uint64_t t, bool first) {
  start = first ? t : std::min(start, t);
  end = first ? t : std::max(end, t);
}

// Fields of a Message record before its data: channel_id, sequence, log_time, publish_time.
constexpr std::size_t kMessageFields = 2 + 4 + 8 + 8;

// A Message record appended in one piece (append_mcap_record(McapMessageView) writes the same
// bytes field by field; this runs for every recorded event).
void append_message_record(std::vector<std::uint8_t>& out, std::uint16_t channel_id, std::uint32_t sequence,
                           std::uint64_t log_time, std::uint64_t publish_time, std::span<const std::uint8_t> data) {
  const std::size_t at = out.size();
  out.resize(at + kMcapRecordPrefix + kMessageFields + data.size());
  std::uint8_t* p = out.data() + at;
  p[0] = mcap_detail::opcode_byte(McapOpcode::message);
  mcap_detail::store_le(p + 1, std::uint64_t{kMessageFields + data.size()});
  p += kMcapRecordPrefix;
  mcap_detail::store_le(p, channel_id);
  mcap_detail::store_le(p + 2, sequence);
  mcap_detail::store_le(p + 6, log_time);
  mcap_detail::store_le(p + 14, publish_time);
  if (!data.empty()) std::memcpy(p + kMessageFields, data.data(), data.size());
}

}  // namespace

McapWriter::McapWriter(McapWriterOptions options, McapSink sink)
    : options_(std::move(options)), sink_(std::move(sink)), zstd_(std::make_unique<mcap_detail::ZstdCompressor>()) {}

McapWriter::McapWriter(McapWriter&&) noexcept = default;
McapWriter& McapWriter::operator=(McapWriter&&) noexcept = default;
McapWriter::~McapWriter() = default;

Result<McapWriter> McapWriter::open(McapWriterOptions options, McapSink sink) {
  if (!sink) return Error{"mcap writer: no sink"};
  if (options.chunk_size == 0) return Error{"mcap writer: chunk_size must be at least 1 byte"};
  McapWriter writer(std::move(options), std::move(sink));
  std::vector<std::uint8_t> start(kMcapMagic.begin(), kMcapMagic.end());
  append_mcap_record(start, McapHeader{writer.options_.profile, writer.options_.library});
  if (auto written = writer.emit(start); !written) return std::move(written).error();
  return writer;
}

Result<void> McapWriter::emit(std::span<const std::uint8_t> bytes) {
  if (auto written = sink_(bytes); !written) {
    failed_ = true;
    return Error{"mcap writer: sink failed at offset " + std::to_string(offset_) + ": " + written.error().text,
                 written.error().code};
  }
  data_crc_ = mcap_crc32(bytes, data_crc_);
  offset_ += bytes.size();
  return {};
}

Result<void> McapWriter::usable() const {
  if (failed_) return Error{"mcap writer: an earlier write to the sink failed; the file is incomplete"};
  if (finished_) return Error{"mcap writer: the file is finished"};
  return {};
}

Result<std::uint16_t> McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                             std::span<const std::uint8_t> data) {
  if (auto ok = usable(); !ok) return std::move(ok).error();
  if (schemas_.size() >= kMaxIds) return Error{"mcap writer: more than 65535 schemas"};
  if (data.size() > std::numeric_limits<std::uint32_t>::max()) return Error{"mcap writer: schema over 4 GiB"};
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back(McapSchema{id, std::string(name), std::string(encoding), {data.begin(), data.end()}});
  schema_written_.push_back(false);
  return id;
}

Result<std::uint16_t> McapWriter::add_channel(std::uint16_t schema_id, std::string_view topic,
                                              std::string_view message_encoding, const McapMap& metadata) {
  if (auto ok = usable(); !ok) return std::move(ok).error();
  if (schema_id > schemas_.size())
    return Error{"mcap writer: channel '" + std::string(topic) + "' names schema " + std::to_string(schema_id) +
                 ", which was not added"};
  if (channels_.size() >= kMaxIds) return Error{"mcap writer: more than 65535 channels"};
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back(McapChannel{id, schema_id, std::string(topic), std::string(message_encoding), metadata});
  channel_written_.push_back(false);
  channel_messages_.push_back(0);
  chunk_channel_messages_.push_back(0);
  return id;
}

// The channel's Schema and Channel records go into the open chunk before its first message.
void McapWriter::declare_channel_in_chunk(std::uint16_t channel_id) {
  if (channel_written_[channel_id - 1]) return;
  const McapChannel& channel = channels_[channel_id - 1];
  if (channel.schema_id != 0 && !schema_written_[channel.schema_id - 1]) {
    append_mcap_record(chunk_records_, schemas_[channel.schema_id - 1]);
    schema_written_[channel.schema_id - 1] = true;
  }
  append_mcap_record(chunk_records_, channel);
  channel_written_[channel_id - 1] = true;
}

Result<void> McapWriter::write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                                       std::uint64_t publish_time_ns, std::span<const std::uint8_t> data) {
  if (auto ok = usable(); !ok) return std::move(ok).error();
  if (channel_id == 0 || channel_id > channels_.size())
    return Error{"mcap writer: message on channel " + std::to_string(channel_id) + ", which was not added"};
  declare_channel_in_chunk(channel_id);

  widen(chunk_start_time_, chunk_end_time_, log_time_ns, chunk_entries_.empty());
  if (chunk_channel_messages_[channel_id - 1]++ == 0) chunk_channels_.push_back(channel_id);
  chunk_entries_.push_back(ChunkEntry{log_time_ns, chunk_records_.size(), channel_id});
  append_message_record(chunk_records_, channel_id, sequence, log_time_ns, publish_time_ns, data);

  widen(statistics_.message_start_time, statistics_.message_end_time, log_time_ns, statistics_.message_count == 0);
  ++statistics_.message_count;
  ++channel_messages_[channel_id - 1];

  if (chunk_records_.size() >= options_.chunk_size) return close_chunk();
  return {};
}

Result<void> McapWriter::add_metadata(std::string_view name, const McapMap& metadata) {
  if (auto ok = usable(); !ok) return std::move(ok).error();
  std::vector<std::uint8_t> record;
  append_mcap_record(record, McapMetadata{std::string(name), metadata});
  const McapMetadataIndex index{offset_, record.size(), std::string(name)};
  if (auto written = emit(record); !written) return written;
  metadata_indexes_.push_back(index);
  ++statistics_.metadata_count;
  return {};
}

Result<void> McapWriter::flush_chunk() {
  if (auto ok = usable(); !ok) return ok;
  return close_chunk();
}

// Compresses the open chunk and gives it to the sink with its Message Index records, in one call.
Result<void> McapWriter::close_chunk() {
  if (chunk_records_.empty()) return {};
  McapChunkView chunk;
  chunk.message_start_time = chunk_start_time_;
  chunk.message_end_time = chunk_end_time_;
  chunk.uncompressed_size = chunk_records_.size();
  chunk.uncompressed_crc = mcap_crc32(chunk_records_);
  if (options_.compression == McapCompression::zstd) {
    auto packed = zstd_->compress(chunk_records_, options_.zstd_level, compressed_);
    if (!packed) {
      failed_ = true;  // the chunk's messages are lost: the file must not go on as if they were not
      return Error{"mcap writer: " + packed.error().text};
    }
    chunk.compression = "zstd";
    chunk.records = std::span<const std::uint8_t>(compressed_).first(packed.value());
  } else {
    chunk.records = chunk_records_;
  }

  chunk_out_.clear();
  append_mcap_record(chunk_out_, chunk);
  McapChunkIndex index;
  index.message_start_time = chunk.message_start_time;
  index.message_end_time = chunk.message_end_time;
  index.chunk_start_offset = offset_;
  index.chunk_length = chunk_out_.size();
  index.compression = chunk.compression;
  index.compressed_size = chunk.records.size();
  index.uncompressed_size = chunk.uncompressed_size;
  append_message_indexes(index);
  index.message_index_length = chunk_out_.size() - index.chunk_length;

  if (auto written = emit(chunk_out_); !written) return written;
  chunk_index_records_.push_back(std::move(index));
  ++statistics_.chunk_count;
  uncompressed_bytes_ += chunk.uncompressed_size;
  compressed_bytes_ += chunk.records.size();
  chunk_records_.clear();
  chunk_entries_.clear();
  chunk_channels_.clear();
  // Above a few chunk sizes, give the memory back (one huge message must not pin it).
  if (chunk_records_.capacity() > 4 * options_.chunk_size) {
    chunk_records_.shrink_to_fit();
    compressed_ = {};
    chunk_out_ = {};
  }
  return {};
}

// The open chunk's Message Index records after its Chunk record in chunk_out_, one per channel in
// ascending id, each listing that channel's messages in written order; their offsets into `index`.
void McapWriter::append_message_indexes(McapChunkIndex& index) {
  std::span<const ChunkEntry> entries = chunk_entries_;
  if (chunk_channels_.size() > 1) {
    // Grouped by channel in one pass: each channel's count becomes where its entries start.
    std::sort(chunk_channels_.begin(), chunk_channels_.end());
    std::uint32_t start = 0;
    for (const std::uint16_t id : chunk_channels_) start += std::exchange(chunk_channel_messages_[id - 1], start);
    grouped_entries_.resize(chunk_entries_.size());
    for (const ChunkEntry& entry : chunk_entries_)
      grouped_entries_[chunk_channel_messages_[entry.channel_id - 1]++] = entry;
    entries = grouped_entries_;
  }
  for (std::size_t i = 0; i < entries.size();) {
    const std::uint16_t id = entries[i].channel_id;
    std::size_t end = i;
    while (end < entries.size() && entries[end].channel_id == id) ++end;
    index.message_index_offsets[id] = offset_ + chunk_out_.size();
    // channel_id, then the entries as an array of (log_time, offset) with its byte length first.
    const std::uint64_t array_bytes = 16 * (end - i);
    const std::size_t at = chunk_out_.size();
    chunk_out_.resize(at + kMcapRecordPrefix + 2 + 4 + array_bytes);
    std::uint8_t* p = chunk_out_.data() + at;
    p[0] = mcap_detail::opcode_byte(McapOpcode::message_index);
    mcap_detail::store_le(p + 1, std::uint64_t{2 + 4 + array_bytes});
    mcap_detail::store_le(p + kMcapRecordPrefix, id);
    mcap_detail::store_le(p + kMcapRecordPrefix + 2, static_cast<std::uint32_t>(array_bytes));
    p += kMcapRecordPrefix + 2 + 4;
    for (; i < end; ++i, p += 16) {
      mcap_detail::store_le(p, entries[i].log_time);
      mcap_detail::store_le(p + 8, entries[i].offset);
    }
  }
  for (const std::uint16_t id : chunk_channels_) chunk_channel_messages_[id - 1] = 0;
}

Result<void> McapWriter::finish() {
  if (auto ok = usable(); !ok) return ok;
  if (auto closed = close_chunk(); !closed) return closed;
  std::vector<std::uint8_t> tail;
  append_mcap_record(tail, McapDataEnd{data_crc_});
  const std::vector<std::uint8_t> summary = build_summary(offset_ + tail.size());
  tail.insert(tail.end(), summary.begin(), summary.end());
  if (auto written = emit(tail); !written) return written;
  finished_ = true;
  return {};
}

// The summary section, the Summary Offsets, the Footer and the closing magic, for a file whose
// summary starts at `summary_start`.
std::vector<std::uint8_t> McapWriter::build_summary(std::uint64_t summary_start) const {
  std::vector<std::uint8_t> out;
  std::vector<McapSummaryOffset> groups;
  // Appends a group of records of one opcode and notes where it lies.
  const auto group = [&](McapOpcode opcode, const auto& records) {
    const std::size_t start = out.size();
    for (const auto& record : records) append_mcap_record(out, record);
    if (out.size() > start)
      groups.push_back({mcap_detail::opcode_byte(opcode), summary_start + start, out.size() - start});
  };
  McapStatistics statistics = statistics_;
  for (std::size_t i = 0; i < channel_messages_.size(); ++i)
    statistics.channel_message_counts[static_cast<std::uint16_t>(i + 1)] = channel_messages_[i];
  statistics.schema_count = static_cast<std::uint16_t>(schemas_.size());
  statistics.channel_count = static_cast<std::uint32_t>(channels_.size());
  group(McapOpcode::schema, schemas_);
  group(McapOpcode::channel, channels_);  // before Statistics, whose per-channel counts name them
  group(McapOpcode::statistics, std::span<const McapStatistics>(&statistics, 1));
  group(McapOpcode::chunk_index, chunk_index_records_);
  group(McapOpcode::metadata_index, metadata_indexes_);

  McapFooter footer;
  footer.summary_start = summary_start;
  footer.summary_offset_start = summary_start + out.size();
  for (const McapSummaryOffset& offset : groups) append_mcap_record(out, offset);
  // The CRC covers the summary, the Summary Offsets and the Footer up to its last offset field.
  std::vector<std::uint8_t> footer_bytes;
  append_mcap_record(footer_bytes, footer);
  std::uint32_t crc = mcap_crc32(out);
  crc = mcap_crc32(std::span<const std::uint8_t>(footer_bytes).first(footer_bytes.size() - 4), crc);
  footer.summary_crc = crc;
  append_mcap_record(out, footer);
  out.insert(out.end(), kMcapMagic.begin(), kMcapMagic.end());
  return out;
}

}  // namespace cosmic

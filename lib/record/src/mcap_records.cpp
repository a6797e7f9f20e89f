// MCAP records to bytes and back (cosmic/mcap_records.hpp). Field order and types follow the
// specification's tables record by record; parsers read the fields they know and ignore the rest.
#include "cosmic/mcap_records.hpp"

#include <zlib.h>

#include <cstdio>
#include <limits>

#include "mcap_bytes.hpp"

namespace cosmic {

using mcap_detail::begin_record;
using mcap_detail::Cursor;
using mcap_detail::end_record;
using mcap_detail::put_raw;
using mcap_detail::put_string;
using mcap_detail::put_u16;
using mcap_detail::put_u32;
using mcap_detail::put_u64;
using mcap_detail::put_u8;

namespace {

// A Map's or Array's byte length goes in front of its entries: written as 0, patched after them.
std::size_t begin_block(std::vector<std::uint8_t>& out) {
  const std::size_t at = out.size();
  put_u32(out, 0);
  return at;
}
void end_block(std::vector<std::uint8_t>& out, std::size_t at) {
  const auto length = static_cast<std::uint32_t>(out.size() - at - 4);
  for (std::size_t i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(length >> (8 * i));
}

void put_map(std::vector<std::uint8_t>& out, const McapMap& map) {
  const std::size_t at = begin_block(out);
  for (const auto& [key, value] : map) {
    put_string(out, key);
    put_string(out, value);
  }
  end_block(out, at);
}

void put_id_map(std::vector<std::uint8_t>& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  const std::size_t at = begin_block(out);
  for (const auto& [id, value] : map) {
    put_u16(out, id);
    put_u64(out, value);
  }
  end_block(out, at);
}

Error too_short(const char* record) {
  return Error{std::string(record) + " record: content ends inside its fields (or a length runs past it)"};
}

// A Map<string, string>: its byte length, then whole entries filling exactly that length.
bool get_map(Cursor& in, McapMap& map) {
  Cursor entries(in.bytes32());
  while (!entries.empty() && !entries.failed()) {
    std::string key = entries.string();
    map[std::move(key)] = entries.string();
  }
  return !entries.failed();
}

bool get_id_map(Cursor& in, std::map<std::uint16_t, std::uint64_t>& map) {
  Cursor entries(in.bytes32());
  while (!entries.empty() && !entries.failed()) {
    const std::uint16_t id = entries.u16();
    map[id] = entries.u64();
  }
  return !entries.failed();
}

}  // namespace

std::uint32_t mcap_crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc) noexcept {
  return static_cast<std::uint32_t>(::crc32_z(crc, bytes.data(), bytes.size()));
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapHeader& header) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::header));
  put_string(out, header.profile);
  put_string(out, header.library);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapFooter& footer) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::footer));
  put_u64(out, footer.summary_start);
  put_u64(out, footer.summary_offset_start);
  put_u32(out, footer.summary_crc);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapSchema& schema) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::schema));
  put_u16(out, schema.id);
  put_string(out, schema.name);
  put_string(out, schema.encoding);
  put_u32(out, static_cast<std::uint32_t>(schema.data.size()));
  put_raw(out, schema.data);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapChannel& channel) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::channel));
  put_u16(out, channel.id);
  put_u16(out, channel.schema_id);
  put_string(out, channel.topic);
  put_string(out, channel.message_encoding);
  put_map(out, channel.metadata);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapMessageView& message) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::message));
  put_u16(out, message.channel_id);
  put_u32(out, message.sequence);
  put_u64(out, message.log_time);
  put_u64(out, message.publish_time);
  put_raw(out, message.data);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapChunkView& chunk) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::chunk));
  put_u64(out, chunk.message_start_time);
  put_u64(out, chunk.message_end_time);
  put_u64(out, chunk.uncompressed_size);
  put_u32(out, chunk.uncompressed_crc);
  put_string(out, chunk.compression);
  put_u64(out, chunk.records.size());
  put_raw(out, chunk.records);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapMessageIndex& index) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::message_index));
  put_u16(out, index.channel_id);
  const std::size_t array_at = begin_block(out);
  for (const auto& [log_time, offset] : index.entries) {
    put_u64(out, log_time);
    put_u64(out, offset);
  }
  end_block(out, array_at);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapChunkIndex& index) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::chunk_index));
  put_u64(out, index.message_start_time);
  put_u64(out, index.message_end_time);
  put_u64(out, index.chunk_start_offset);
  put_u64(out, index.chunk_length);
  put_id_map(out, index.message_index_offsets);
  put_u64(out, index.message_index_length);
  put_string(out, index.compression);
  put_u64(out, index.compressed_size);
  put_u64(out, index.uncompressed_size);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapStatistics& s) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::statistics));
  put_u64(out, s.message_count);
  put_u16(out, s.schema_count);
  put_u32(out, s.channel_count);
  put_u32(out, s.attachment_count);
  put_u32(out, s.metadata_count);
  put_u32(out, s.chunk_count);
  put_u64(out, s.message_start_time);
  put_u64(out, s.message_end_time);
  put_id_map(out, s.channel_message_counts);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapMetadata& metadata) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::metadata));
  put_string(out, metadata.name);
  put_map(out, metadata.metadata);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapMetadataIndex& index) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::metadata_index));
  put_u64(out, index.offset);
  put_u64(out, index.length);
  put_string(out, index.name);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapSummaryOffset& offset) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::summary_offset));
  put_u8(out, offset.group_opcode);
  put_u64(out, offset.group_start);
  put_u64(out, offset.group_length);
  end_record(out, at);
}

void append_mcap_record(std::vector<std::uint8_t>& out, const McapDataEnd& data_end) {
  const std::size_t at = begin_record(out, mcap_detail::opcode_byte(McapOpcode::data_end));
  put_u32(out, data_end.data_section_crc);
  end_record(out, at);
}

Result<McapHeader> parse_mcap_header(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapHeader h;
  h.profile = in.string();
  h.library = in.string();
  if (in.failed()) return too_short("header");
  return h;
}

Result<McapFooter> parse_mcap_footer(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapFooter f;
  f.summary_start = in.u64();
  f.summary_offset_start = in.u64();
  f.summary_crc = in.u32();
  if (in.failed()) return too_short("footer");
  return f;
}

Result<McapSchema> parse_mcap_schema(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapSchema s;
  s.id = in.u16();
  s.name = in.string();
  s.encoding = in.string();
  const auto data = in.bytes32();
  if (in.failed()) return too_short("schema");
  s.data.assign(data.begin(), data.end());
  return s;
}

Result<McapChannel> parse_mcap_channel(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapChannel c;
  c.id = in.u16();
  c.schema_id = in.u16();
  c.topic = in.string();
  c.message_encoding = in.string();
  if (!get_map(in, c.metadata) || in.failed()) return too_short("channel");
  return c;
}

Result<McapMessageView> parse_mcap_message(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapMessageView m;
  m.channel_id = in.u16();
  m.sequence = in.u32();
  m.log_time = in.u64();
  m.publish_time = in.u64();
  if (in.failed()) return too_short("message");
  m.data = in.rest();  // the data runs to the end of the record: Message is never extended
  return m;
}

Result<McapChunkView> parse_mcap_chunk(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapChunkView c;
  c.message_start_time = in.u64();
  c.message_end_time = in.u64();
  c.uncompressed_size = in.u64();
  c.uncompressed_crc = in.u32();
  c.compression = in.string();
  c.records = in.bytes64();
  if (in.failed()) return too_short("chunk");
  return c;
}

Result<McapMessageIndex> parse_mcap_message_index(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapMessageIndex index;
  index.channel_id = in.u16();
  Cursor entries(in.bytes32());
  while (!entries.empty() && !entries.failed()) {
    const std::uint64_t log_time = entries.u64();
    index.entries.emplace_back(log_time, entries.u64());
  }
  if (in.failed() || entries.failed()) return too_short("message index");
  return index;
}

Result<McapChunkIndex> parse_mcap_chunk_index(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapChunkIndex c;
  c.message_start_time = in.u64();
  c.message_end_time = in.u64();
  c.chunk_start_offset = in.u64();
  c.chunk_length = in.u64();
  const bool offsets_ok = get_id_map(in, c.message_index_offsets);
  c.message_index_length = in.u64();
  c.compression = in.string();
  c.compressed_size = in.u64();
  c.uncompressed_size = in.u64();
  if (!offsets_ok || in.failed()) return too_short("chunk index");
  return c;
}

Result<McapStatistics> parse_mcap_statistics(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapStatistics s;
  s.message_count = in.u64();
  s.schema_count = in.u16();
  s.channel_count = in.u32();
  s.attachment_count = in.u32();
  s.metadata_count = in.u32();
  s.chunk_count = in.u32();
  s.message_start_time = in.u64();
  s.message_end_time = in.u64();
  if (!get_id_map(in, s.channel_message_counts) || in.failed()) return too_short("statistics");
  return s;
}

Result<McapMetadata> parse_mcap_metadata(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapMetadata m;
  m.name = in.string();
  if (!get_map(in, m.metadata) || in.failed()) return too_short("metadata");
  return m;
}

Result<McapMetadataIndex> parse_mcap_metadata_index(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapMetadataIndex m;
  m.offset = in.u64();
  m.length = in.u64();
  m.name = in.string();
  if (in.failed()) return too_short("metadata index");
  return m;
}

Result<McapSummaryOffset> parse_mcap_summary_offset(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapSummaryOffset s;
  s.group_opcode = in.u8();
  s.group_start = in.u64();
  s.group_length = in.u64();
  if (in.failed()) return too_short("summary offset");
  return s;
}

Result<McapDataEnd> parse_mcap_data_end(std::span<const std::uint8_t> content) {
  Cursor in(content);
  McapDataEnd d;
  d.data_section_crc = in.u32();
  if (in.failed()) return too_short("data end");
  return d;
}

McapRecordAt mcap_record_at(std::span<const std::uint8_t> bytes, std::uint64_t at) noexcept {
  McapRecordAt found;
  const std::uint64_t size = bytes.size();
  if (at > size || size - at < kMcapRecordPrefix) {
    found.incomplete = true;
    found.needed = at + kMcapRecordPrefix;
    return found;
  }
  const auto prefix = bytes.subspan(static_cast<std::size_t>(at), kMcapRecordPrefix);
  const std::uint64_t length = mcap_detail::get_le(prefix.subspan(1));
  const std::uint64_t content_at = at + kMcapRecordPrefix;
  if (length > size - content_at) {
    found.incomplete = true;
    // Saturating: a garbage length near 2^64 must not wrap around.
    const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
    found.needed = length > max - content_at ? max : content_at + length;
    return found;
  }
  found.record.opcode = prefix[0];
  found.record.offset = at;
  found.record.content = bytes.subspan(static_cast<std::size_t>(content_at), static_cast<std::size_t>(length));
  return found;
}

std::string mcap_opcode_name(std::uint8_t opcode) {
  static constexpr const char* kNames[] = {
      "header",     "footer",        "schema",         "channel",        "message",
      "chunk",      "message index", "chunk index",    "attachment",     "attachment index",
      "statistics", "metadata",      "metadata index", "summary offset", "data end"};
  if (opcode >= 0x01 && opcode <= 0x0F) return kNames[opcode - 1];
  char text[24];
  std::snprintf(text, sizeof text, "unknown (0x%02x)", opcode);
  return text;
}

}  // namespace cosmic

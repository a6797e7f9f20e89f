// scan_mcap and read_mcap (cosmic/mcap_reader.hpp): the data section record by record, chunks
// decompressed one at a time, then the summary when the file is whole.
#include "cosmic/mcap_reader.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include "mcap_bytes.hpp"
#include "mcap_compression.hpp"
#include "mcap_summary.hpp"

namespace cosmic {

using mcap_detail::error_at;

namespace {

// The state of one scan: what was declared so far, the chunk buffer, how the file ends.
class Scanner {
 public:
  Scanner(std::span<const std::uint8_t> file, const McapMessageCallback& on_message, const McapReadLimits& limits)
      : file_(file), on_message_(on_message), limits_(limits) {}

  Result<McapScan> run();

 private:
  Result<void> walk_data_section();
  Result<void> data_record(const McapRecordView& r, bool& stop);
  Result<void> chunk(const McapRecordView& r);
  Result<void> chunk_record(const McapRecordView& inner, std::uint64_t chunk_offset);
  Result<void> schema(std::span<const std::uint8_t> content, std::uint64_t offset);
  Result<void> channel(std::span<const std::uint8_t> content, std::uint64_t offset);
  Result<void> message(std::span<const std::uint8_t> content, std::uint64_t offset);
  Result<void> read_summary();
  void truncate(std::string why) {
    out_.truncated = true;
    out_.truncation = std::move(why);
  }

  std::span<const std::uint8_t> file_;
  const McapMessageCallback& on_message_;
  const McapReadLimits& limits_;

  McapScan out_;
  std::map<std::uint16_t, std::size_t> schema_at_;   // id -> index in out_.schemas
  std::map<std::uint16_t, std::size_t> channel_at_;  // id -> index in out_.channels
  std::vector<std::uint8_t> chunk_buffer_;           // reused for every chunk

  std::optional<McapFooter> footer_;  // the file ends with Footer and magic: it is whole
  std::uint64_t data_limit_ = 0;      // where the data section's records must end
  std::uint64_t header_end_ = 0;
  bool data_end_seen_ = false;
  bool callback_failed_ = false;
};

Result<McapScan> Scanner::run() {
  const std::size_t magic = kMcapMagic.size();
  const std::size_t head = std::min(file_.size(), magic);
  if (!std::equal(file_.begin(), file_.begin() + static_cast<std::ptrdiff_t>(head), kMcapMagic.begin()))
    return error_at(0, "no MCAP magic at the start of the file");
  if (file_.size() < magic) {
    truncate("the file ends inside the opening magic, after " + std::to_string(file_.size()) + " bytes");
    return std::move(out_);
  }
  out_.complete_bytes = magic;
  data_limit_ = file_.size();
  if (file_.size() >= magic + kMcapRecordPrefix + kMcapFooterTail) {
    footer_ = mcap_detail::footer_in_tail(file_.last(kMcapFooterTail));
    if (footer_) {
      data_limit_ = file_.size() - kMcapFooterTail;
      if (footer_->summary_start != 0 && footer_->summary_start <= data_limit_) data_limit_ = footer_->summary_start;
    }
  }
  if (auto walked = walk_data_section(); !walked) return std::move(walked).error();
  if (footer_ && !out_.truncated) {
    if (auto summary = read_summary(); !summary) return std::move(summary).error();
    out_.complete_bytes = file_.size();
  }
  return std::move(out_);
}

Result<void> Scanner::walk_data_section() {
  const auto data = file_.first(static_cast<std::size_t>(data_limit_));
  std::uint64_t at = kMcapMagic.size();
  while (at < data.size()) {
    const McapRecordAt found = mcap_record_at(data, at);
    if (found.incomplete) {
      const std::string what = found.needed - at == kMcapRecordPrefix
                                   ? "a record's opcode and length"
                                   : "the " + mcap_opcode_name(data[static_cast<std::size_t>(at)]) + " record";
      if (footer_)
        return error_at(at, what + " runs past the end of the data section at offset " + std::to_string(data_limit_));
      truncate("the file ends at offset " + std::to_string(file_.size()) + " inside " + what + " that starts at " +
               std::to_string(at) + " (no footer: the recording was cut short)");
      return {};
    }
    const McapRecordView& r = found.record;
    if (at == kMcapMagic.size() && r.opcode != static_cast<std::uint8_t>(McapOpcode::header))
      return error_at(at, "the first record is " + mcap_opcode_name(r.opcode) + ", not a header");
    bool stop = false;
    if (auto handled = data_record(r, stop); !handled) return handled;
    at += r.length();
    out_.complete_bytes = at;
    if (stop) break;
  }
  if (footer_ && header_end_ == 0) return error_at(kMcapMagic.size(), "the file has a footer but no header record");
  if (!footer_ && !out_.truncated)
    truncate("the file ends at offset " + std::to_string(file_.size()) +
             (data_end_seen_ ? " after its data section, without summary and footer"
                             : " after a complete record, without data end and footer (the recording was cut short)"));
  return {};
}

Result<void> Scanner::data_record(const McapRecordView& r, bool& stop) {
  switch (static_cast<McapOpcode>(r.opcode)) {
    case McapOpcode::header: {
      if (r.offset != kMcapMagic.size()) return error_at(r.offset, "a second header");
      auto header = parse_mcap_header(r.content);
      if (!header) return error_at(r.offset, header.error().text);
      out_.header = std::move(header).value();
      header_end_ = r.offset + r.length();
      return {};
    }
    case McapOpcode::schema:
      return schema(r.content, r.offset);
    case McapOpcode::channel:
      return channel(r.content, r.offset);
    case McapOpcode::message:
      return message(r.content, r.offset);
    case McapOpcode::chunk:
      return chunk(r);
    case McapOpcode::metadata: {
      auto metadata = parse_mcap_metadata(r.content);
      if (!metadata) return error_at(r.offset, metadata.error().text);
      out_.metadata.push_back(std::move(metadata).value());
      return {};
    }
    case McapOpcode::data_end: {
      auto data_end = parse_mcap_data_end(r.content);
      if (!data_end) return error_at(r.offset, data_end.error().text);
      // The data section's CRC covers every byte before Data End, the opening magic included.
      const std::uint32_t crc = data_end.value().data_section_crc;
      if (crc != 0 && crc != mcap_crc32(file_.first(static_cast<std::size_t>(r.offset))))
        return error_at(r.offset, "data section CRC mismatch (data end says " + std::to_string(crc) +
                                      ", the bytes before it give " +
                                      std::to_string(mcap_crc32(file_.first(static_cast<std::size_t>(r.offset)))) +
                                      ")");
      data_end_seen_ = stop = true;
      return {};
    }
    case McapOpcode::footer:  // a file without Data End: its data section ends here
      stop = true;
      return {};
    default:  // message indexes (the scan needs none), attachments, records of later versions
      return {};
  }
}

Result<void> Scanner::chunk(const McapRecordView& r) {
  auto parsed = parse_mcap_chunk(r.content);
  if (!parsed) return error_at(r.offset, parsed.error().text);
  const McapChunkView& c = parsed.value();
  const std::uint64_t ratio_cap = std::max(limits_.min_ratio_floor, c.records.size() * limits_.max_ratio);
  if (c.uncompressed_size > limits_.max_chunk_bytes || c.uncompressed_size > ratio_cap)
    return error_at(r.offset, "chunk claims " + std::to_string(c.uncompressed_size) + " uncompressed bytes from " +
                                  std::to_string(c.records.size()) + ", over the limit of " +
                                  std::to_string(std::min(limits_.max_chunk_bytes, ratio_cap)));
  chunk_buffer_.resize(static_cast<std::size_t>(c.uncompressed_size));
  if (auto unpacked = mcap_detail::decompress_chunk(c.compression, c.records, chunk_buffer_); !unpacked)
    return error_at(r.offset, "chunk does not decompress: " + unpacked.error().text);
  if (c.uncompressed_crc != 0 && c.uncompressed_crc != mcap_crc32(chunk_buffer_))
    return error_at(r.offset, "chunk CRC mismatch (the chunk says " + std::to_string(c.uncompressed_crc) +
                                  ", its records give " + std::to_string(mcap_crc32(chunk_buffer_)) + ")");
  ++out_.chunk_count;
  std::uint64_t at = 0;
  while (at < chunk_buffer_.size()) {
    const McapRecordAt found = mcap_record_at(chunk_buffer_, at);
    if (found.incomplete)
      return error_at(r.offset, "chunk: the record at byte " + std::to_string(at) +
                                    " of its records runs past their end (" + std::to_string(chunk_buffer_.size()) +
                                    " bytes)");
    if (auto handled = chunk_record(found.record, r.offset); !handled) return handled;
    at += found.record.length();
  }
  return {};
}

// A record inside a chunk: errors name the chunk's offset in the file and the record's in the chunk.
Result<void> Scanner::chunk_record(const McapRecordView& inner, std::uint64_t chunk_offset) {
  Result<void> handled;
  switch (static_cast<McapOpcode>(inner.opcode)) {
    case McapOpcode::schema:
      handled = schema(inner.content, chunk_offset);
      break;
    case McapOpcode::channel:
      handled = channel(inner.content, chunk_offset);
      break;
    case McapOpcode::message:
      handled = message(inner.content, chunk_offset);
      break;
    default:  // nothing else belongs in a chunk; a later version's record is skipped
      break;
  }
  if (handled || callback_failed_) return handled;  // the caller's own error comes back as it was
  return Error{handled.error().text + " (record at byte " + std::to_string(inner.offset) + " of the chunk's records)",
               handled.error().code};
}

// A Schema or Channel record: kept the first time its id appears; repeated, it must be identical.
template <typename Record>
Result<void> declare(Record record, std::map<std::uint16_t, std::size_t>& at, std::vector<Record>& records,
                     const char* kind, std::uint64_t offset) {
  if (const auto known = at.find(record.id); known != at.end()) {
    if (records[known->second] == record) return {};
    return error_at(offset, std::string(kind) + " " + std::to_string(record.id) + " redefined differently");
  }
  at[record.id] = records.size();
  records.push_back(std::move(record));
  return {};
}

Result<void> Scanner::schema(std::span<const std::uint8_t> content, std::uint64_t offset) {
  auto parsed = parse_mcap_schema(content);
  if (!parsed) return error_at(offset, parsed.error().text);
  if (parsed.value().id == 0) return {};  // id 0 is invalid: the specification says to ignore it
  return declare(std::move(parsed).value(), schema_at_, out_.schemas, "schema", offset);
}

Result<void> Scanner::channel(std::span<const std::uint8_t> content, std::uint64_t offset) {
  auto parsed = parse_mcap_channel(content);
  if (!parsed) return error_at(offset, parsed.error().text);
  const McapChannel& c = parsed.value();
  if (c.schema_id != 0 && !schema_at_.contains(c.schema_id))
    return error_at(offset, "channel " + std::to_string(c.id) + " ('" + c.topic + "') names schema " +
                                std::to_string(c.schema_id) + ", not declared before it");
  return declare(std::move(parsed).value(), channel_at_, out_.channels, "channel", offset);
}

Result<void> Scanner::message(std::span<const std::uint8_t> content, std::uint64_t offset) {
  auto parsed = parse_mcap_message(content);
  if (!parsed) return error_at(offset, parsed.error().text);
  const McapMessageView& m = parsed.value();
  const auto known = channel_at_.find(m.channel_id);
  if (known == channel_at_.end())
    return error_at(offset, "message on channel " + std::to_string(m.channel_id) + ", not declared before it");
  ++out_.message_count;
  if (!on_message_) return {};
  auto taken = on_message_(m, out_.channels[known->second]);
  callback_failed_ = !taken;
  return taken;
}

Result<void> Scanner::read_summary() {
  const std::uint64_t footer_offset = file_.size() - kMcapFooterTail;
  auto start = mcap_detail::summary_region_start(*footer_, header_end_, footer_offset);
  if (!start) return std::move(start).error();
  McapSummary summary;
  summary.header = out_.header;
  summary.footer = *footer_;
  if (start.value()) {
    const std::uint64_t begin = *start.value();
    const auto region = file_.subspan(static_cast<std::size_t>(begin), static_cast<std::size_t>(footer_offset - begin));
    if (auto parsed = mcap_detail::parse_summary_region(region, begin, file_.last(kMcapFooterTail), summary); !parsed)
      return parsed;
    out_.summary = std::move(summary);
  }
  return {};
}

}  // namespace

Result<McapScan> scan_mcap(std::span<const std::uint8_t> file, const McapMessageCallback& on_message,
                           const McapReadLimits& limits) {
  Scanner scanner(file, on_message, limits);
  return scanner.run();
}

Result<McapFile> read_mcap(std::span<const std::uint8_t> file, const McapReadLimits& limits) {
  std::vector<McapMessage> messages;
  const McapMessageCallback keep = [&messages](const McapMessageView& m, const McapChannel&) -> Result<void> {
    messages.push_back(
        McapMessage{m.channel_id, m.sequence, m.log_time, m.publish_time, {m.data.begin(), m.data.end()}});
    return {};
  };
  auto scan = scan_mcap(file, keep, limits);
  if (!scan) return std::move(scan).error();
  McapFile out;
  static_cast<McapScan&>(out) = std::move(scan).value();
  out.messages = std::move(messages);
  return out;
}

}  // namespace cosmic

// The Footer and the summary section (mcap_summary.hpp), and read_mcap_summary, which reads only
// them (and the Header) through the caller's read_at.
#include "mcap_summary.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/mcap_reader.hpp"
#include "mcap_bytes.hpp"

namespace cosmic {

namespace mcap_detail {

namespace {

// Headers hold two short strings; more than this is not a header but damage.
constexpr std::uint64_t kMaxHeaderContent = 1 << 20;
constexpr std::size_t kFooterRecord = kMcapRecordPrefix + kMcapFooterContent;

bool has_magic(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= kMcapMagic.size() && std::equal(kMcapMagic.begin(), kMcapMagic.end(), bytes.begin());
}

// One summary record into `summary`; records it does not know (attachment indexes, later
// additions to the format) are skipped.
Result<void> add_summary_record(const McapRecordView& r, McapSummary& summary) {
  const auto keep = [&](auto parsed, auto& into) -> Result<void> {
    if (!parsed) return error_at(r.offset, "summary: " + parsed.error().text);
    into.push_back(std::move(parsed).value());
    return {};
  };
  switch (static_cast<McapOpcode>(r.opcode)) {
    case McapOpcode::schema:
      return keep(parse_mcap_schema(r.content), summary.schemas);
    case McapOpcode::channel:
      return keep(parse_mcap_channel(r.content), summary.channels);
    case McapOpcode::chunk_index:
      return keep(parse_mcap_chunk_index(r.content), summary.chunk_indexes);
    case McapOpcode::metadata_index:
      return keep(parse_mcap_metadata_index(r.content), summary.metadata_indexes);
    case McapOpcode::summary_offset:
      return keep(parse_mcap_summary_offset(r.content), summary.summary_offsets);
    case McapOpcode::statistics: {
      auto statistics = parse_mcap_statistics(r.content);
      if (!statistics) return error_at(r.offset, "summary: " + statistics.error().text);
      summary.statistics = std::move(statistics).value();
      return {};
    }
    default:
      return {};
  }
}

}  // namespace

Error error_at(std::uint64_t offset, std::string_view text) {
  return Error{"mcap offset " + std::to_string(offset) + ": " + std::string(text)};
}

std::optional<McapFooter> footer_in_tail(std::span<const std::uint8_t> tail) {
  if (tail.size() != kMcapFooterTail || !has_magic(tail.subspan(kFooterRecord))) return std::nullopt;
  if (tail[0] != static_cast<std::uint8_t>(McapOpcode::footer) || get_le(tail.subspan(1, 8)) != kMcapFooterContent)
    return std::nullopt;
  auto footer = parse_mcap_footer(tail.subspan(kMcapRecordPrefix, kMcapFooterContent));
  if (!footer) return std::nullopt;
  return footer.value();
}

Result<std::optional<std::uint64_t>> summary_region_start(const McapFooter& footer, std::uint64_t header_end,
                                                          std::uint64_t footer_offset) {
  const std::uint64_t start = footer.summary_start != 0 ? footer.summary_start : footer.summary_offset_start;
  if (start == 0) return std::optional<std::uint64_t>();
  if (start < header_end || start > footer_offset ||
      (footer.summary_offset_start != 0 &&
       (footer.summary_offset_start < start || footer.summary_offset_start > footer_offset)))
    return error_at(footer_offset, "footer: summary_start " + std::to_string(footer.summary_start) +
                                       " or summary_offset_start " + std::to_string(footer.summary_offset_start) +
                                       " lies outside the file's records (" + std::to_string(header_end) + ".." +
                                       std::to_string(footer_offset) + ")");
  return std::optional<std::uint64_t>(start);
}

Result<void> parse_summary_region(std::span<const std::uint8_t> region, std::uint64_t start,
                                  std::span<const std::uint8_t> footer_record, McapSummary& summary) {
  const McapFooter& footer = summary.footer;
  if (footer.summary_crc != 0) {
    // Everything from the summary's start through the Footer's summary_offset_start field.
    std::uint32_t crc = mcap_crc32(region);
    crc = mcap_crc32(footer_record.first(kFooterRecord - 4), crc);
    if (crc != footer.summary_crc)
      return error_at(start, "summary CRC mismatch (footer says " + std::to_string(footer.summary_crc) +
                                 ", the bytes give " + std::to_string(crc) + ")");
  }
  std::uint64_t at = 0;
  while (at < region.size()) {
    const McapRecordAt found = mcap_record_at(region, at);
    if (found.incomplete)
      return error_at(start + at,
                      "summary: a record runs past the footer at offset " + std::to_string(start + region.size()));
    McapRecordView record = found.record;
    record.offset += start;
    if (auto added = add_summary_record(record, summary); !added) return added;
    at += found.record.length();
  }
  return {};
}

// Reads `count` bytes at `offset` through read_at.
Result<std::vector<std::uint8_t>> read_range(const McapReadAt& read_at, std::uint64_t offset, std::uint64_t count) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(count));
  if (auto read = read_at(offset, bytes); !read) return std::move(read).error();
  return bytes;
}

}  // namespace mcap_detail

using mcap_detail::error_at;

Result<std::optional<McapSummary>> read_mcap_summary(std::uint64_t file_size, const McapReadAt& read_at,
                                                     const McapReadLimits& limits) {
  using mcap_detail::read_range;
  constexpr std::uint64_t kHeadBytes = kMcapMagic.size() + kMcapRecordPrefix;
  if (file_size < kHeadBytes + kMcapFooterTail)
    return error_at(file_size, "the file is too short for a header and a footer (" + std::to_string(file_size) +
                                   " bytes): truncated, or not MCAP");
  auto head = read_range(read_at, 0, kHeadBytes);
  if (!head) return std::move(head).error();
  if (!mcap_detail::has_magic(head.value())) return error_at(0, "no MCAP magic at the start of the file");
  if (head.value()[kMcapMagic.size()] != static_cast<std::uint8_t>(McapOpcode::header))
    return error_at(kMcapMagic.size(), "the first record is not a header");
  const std::uint64_t header_length = mcap_detail::get_le(std::span(head.value()).subspan(kMcapMagic.size() + 1));
  const std::uint64_t footer_offset = file_size - kMcapFooterTail;
  if (header_length > mcap_detail::kMaxHeaderContent || kHeadBytes + header_length > footer_offset)
    return error_at(kMcapMagic.size(), "header length " + std::to_string(header_length) + " is not plausible");

  auto tail = read_range(read_at, footer_offset, kMcapFooterTail);
  if (!tail) return std::move(tail).error();
  const auto footer = mcap_detail::footer_in_tail(tail.value());
  if (!footer)
    return error_at(footer_offset,
                    "no footer and closing magic at the end: the file is truncated or still being "
                    "written (scan it from the start instead)");
  const std::uint64_t header_end = kHeadBytes + header_length;
  auto start = mcap_detail::summary_region_start(*footer, header_end, footer_offset);
  if (!start) return std::move(start).error();
  if (!start.value()) return std::optional<McapSummary>();
  const std::uint64_t region_start = *start.value();
  if (footer_offset - region_start > limits.max_summary_bytes)
    return error_at(region_start, "summary of " + std::to_string(footer_offset - region_start) +
                                      " bytes is over the limit of " + std::to_string(limits.max_summary_bytes));

  McapSummary summary;
  summary.footer = *footer;
  auto header_content = read_range(read_at, kHeadBytes, header_length);
  if (!header_content) return std::move(header_content).error();
  auto header = parse_mcap_header(header_content.value());
  if (!header) return error_at(kMcapMagic.size(), header.error().text);
  summary.header = std::move(header).value();

  auto region = read_range(read_at, region_start, footer_offset - region_start);
  if (!region) return std::move(region).error();
  if (auto parsed = mcap_detail::parse_summary_region(region.value(), region_start, tail.value(), summary); !parsed)
    return std::move(parsed).error();
  return std::optional<McapSummary>(std::move(summary));
}

Result<std::optional<McapSummary>> read_mcap_summary(std::span<const std::uint8_t> file, const McapReadLimits& limits) {
  const McapReadAt read_at = [file](std::uint64_t offset, std::span<std::uint8_t> out) -> Result<void> {
    if (offset > file.size() || out.size() > file.size() - offset)
      return error_at(offset, "read of " + std::to_string(out.size()) + " bytes past the end of the file");
    if (!out.empty()) std::memcpy(out.data(), file.data() + offset, out.size());
    return {};
  };
  return read_mcap_summary(file.size(), read_at, limits);
}

}  // namespace cosmic

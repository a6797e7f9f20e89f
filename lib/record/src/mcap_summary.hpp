// The end of an MCAP file, shared by the whole-file scan and the summary-only reader: the Footer
// and closing magic, and the summary section the Footer points at. Internal to cosmic_mcap.
//
// Threads: pure functions; any thread.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_records.hpp"
#include "cosmic/result.hpp"

namespace cosmic::mcap_detail {

// "mcap offset N: TEXT": every reader error names the byte it concerns.
Error error_at(std::uint64_t offset, std::string_view text);

// The Footer in `tail` (the file's last kMcapFooterTail bytes), or nullopt when they are not a
// Footer record followed by the closing magic (the file is truncated or still being written).
std::optional<McapFooter> footer_in_tail(std::span<const std::uint8_t> tail);

// Where the records the Footer covers begin (its summary, else its Summary Offsets), checked to lie
// between the end of the Header and the Footer; nullopt when the Footer names neither.
Result<std::optional<std::uint64_t>> summary_region_start(const McapFooter& footer, std::uint64_t header_end,
                                                          std::uint64_t footer_offset);

// `region` holds the file's bytes from `start` up to the Footer record, `footer_record` that
// record's bytes: checks the Footer's CRC (when not 0) and reads the records into `summary`.
Result<void> parse_summary_region(std::span<const std::uint8_t> region, std::uint64_t start,
                                  std::span<const std::uint8_t> footer_record, McapSummary& summary);

}  // namespace cosmic::mcap_detail

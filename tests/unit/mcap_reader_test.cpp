// The MCAP readers (cosmic/mcap_reader.hpp): a file cut at every byte yields a prefix of its
// messages (every complete chunk) and never an error; damage gives an error naming its offset
// (magic, lengths, CRCs, chunks that do not decompress or claim too much, undeclared channels);
// lz4 chunks and messages outside chunks as other writers write them; the summary read without
// touching the data section.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lz4frame.h>

#include <algorithm>
#include <string>
#include <utility>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_records.hpp"
#include "cosmic/mcap_writer.hpp"
#include "mcap_test_support.hpp"

namespace cosmic {
namespace {

using mcap_test::build_file;
using mcap_test::Bytes;
using mcap_test::messages_of;
using mcap_test::small_chunks;
using mcap_test::write_sample;
using testing::HasSubstr;

std::string error_of(std::span<const std::uint8_t> file) {
  auto read = read_mcap(file);
  return read ? "(no error)" : read.error().text;
}

std::string offset_text(std::uint64_t offset) { return "mcap offset " + std::to_string(offset) + ":"; }

McapSummary summary_of(const Bytes& file) {
  auto summary = read_mcap_summary(file);
  EXPECT_TRUE(summary && summary.value());
  return summary && summary.value() ? *summary.value() : McapSummary{};
}

class McapTruncation : public testing::TestWithParam<McapCompression> {};

TEST_P(McapTruncation, EveryCutYieldsAPrefixOfTheMessages) {
  const auto sample = write_sample(small_chunks(GetParam(), 200), 40);
  const Bytes& file = sample.written.file;
  const auto chunks = summary_of(file).chunk_indexes;
  ASSERT_GT(chunks.size(), 3u);
  std::size_t previous = 0;
  for (std::size_t n = 0; n < file.size(); ++n) {
    auto read = read_mcap(std::span(file).first(n));
    ASSERT_TRUE(read) << "cut at " << n << ": " << read.error().text;
    const McapFile& f = read.value();
    ASSERT_TRUE(f.truncated) << "cut at " << n;
    EXPECT_FALSE(f.truncation.empty());
    EXPECT_LE(f.complete_bytes, n);
    ASSERT_LE(f.messages.size(), sample.messages.size());
    ASSERT_TRUE(std::equal(f.messages.begin(), f.messages.end(), sample.messages.begin())) << "cut at " << n;
    EXPECT_GE(f.messages.size(), previous) << "cut at " << n;
    previous = f.messages.size();
  }
  EXPECT_EQ(previous, sample.messages.size());  // all chunks are complete before the summary
}

// A chunk counts once its last byte is there, not before.
TEST_P(McapTruncation, KeepsEveryCompleteChunk) {
  const auto sample = write_sample(small_chunks(GetParam(), 200), 40);
  const Bytes& file = sample.written.file;
  std::size_t before = 0;
  for (const McapChunkIndex& chunk : summary_of(file).chunk_indexes) {
    const std::uint64_t end = chunk.chunk_start_offset + chunk.chunk_length;
    const auto cut_inside = messages_of(std::span(file).first(end - 1));
    const auto cut_after = messages_of(std::span(file).first(end));
    EXPECT_EQ(cut_inside.size(), before);
    std::size_t in_chunk = 0;
    for (const auto& [channel, offset] : chunk.message_index_offsets) {
      auto index = parse_mcap_message_index(mcap_record_at(file, offset).record.content);
      in_chunk += index.value().entries.size();
    }
    EXPECT_EQ(cut_after.size(), before + in_chunk);
    before = cut_after.size();
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapTruncation, testing::Values(McapCompression::zstd, McapCompression::none),
                         [](const auto& info) { return info.param == McapCompression::zstd ? "zstd" : "none"; });

TEST(McapTruncation, SaysWhereTheFileEnds) {
  const auto sample = write_sample(small_chunks(McapCompression::zstd, 200), 40);
  const Bytes& file = sample.written.file;
  const McapChunkIndex second = summary_of(file).chunk_indexes.at(1);
  auto read = read_mcap(std::span(file).first(second.chunk_start_offset + 20));
  ASSERT_TRUE(read);
  EXPECT_THAT(read.value().truncation,
              HasSubstr("chunk record that starts at " + std::to_string(second.chunk_start_offset)));
  EXPECT_EQ(read.value().complete_bytes, second.chunk_start_offset);
  EXPECT_FALSE(read.value().summary);
  // Without a footer there is no summary to read on its own.
  auto summary = read_mcap_summary(std::span(file).first(file.size() - 1));
  ASSERT_FALSE(summary);
  EXPECT_THAT(summary.error().text, HasSubstr("truncated"));
}

TEST(McapDamage, BadMagicIsAnErrorAtOffsetZero) {
  auto file = write_sample(small_chunks(McapCompression::none), 10).written.file;
  file[1] = 'X';
  EXPECT_THAT(error_of(file), HasSubstr(offset_text(0)));
  EXPECT_THAT(error_of(Bytes{'G', 'I', 'F'}), HasSubstr("magic"));
  file[1] = 'M';
  file[5] = '1';  // another major version
  EXPECT_THAT(error_of(file), HasSubstr(offset_text(0)));
}

TEST(McapDamage, ChunkCrcMismatchNamesTheChunk) {
  auto file = write_sample(small_chunks(McapCompression::none), 30).written.file;
  const McapChunkIndex chunk = summary_of(file).chunk_indexes.at(1);
  // The last byte of the chunk's (uncompressed) records: inside a message's data.
  file[chunk.chunk_start_offset + chunk.chunk_length - 1] ^= 0x5A;
  const std::string error = error_of(file);
  EXPECT_THAT(error, HasSubstr(offset_text(chunk.chunk_start_offset)));
  EXPECT_THAT(error, HasSubstr("CRC"));
}

TEST(McapDamage, DamagedZstdChunkNamesTheChunk) {
  auto file = write_sample(small_chunks(McapCompression::zstd), 30).written.file;
  const McapChunkIndex chunk = summary_of(file).chunk_indexes.at(2);
  const std::uint64_t records_at = chunk.chunk_start_offset + chunk.chunk_length - chunk.compressed_size;
  for (std::uint64_t i = 0; i < chunk.compressed_size; ++i) file[records_at + i] ^= 0xFF;
  EXPECT_THAT(error_of(file), HasSubstr(offset_text(chunk.chunk_start_offset)));
}

// In a file that has its footer, a length past the data section is damage, not truncation.
TEST(McapDamage, ALengthPastTheSectionIsAnError) {
  auto file = write_sample(small_chunks(McapCompression::zstd), 30).written.file;
  const McapChunkIndex chunk = summary_of(file).chunk_indexes.at(1);
  file[chunk.chunk_start_offset + 8] = 0x40;  // the length's top byte: 2^62 and more
  const std::string error = error_of(file);
  EXPECT_THAT(error, HasSubstr(offset_text(chunk.chunk_start_offset)));
  EXPECT_THAT(error, HasSubstr("runs past the end of the data section"));
}

TEST(McapDamage, DataSectionCrcCoversTheHeader) {
  auto file = write_sample(small_chunks(McapCompression::zstd), 30).written.file;
  const McapSummary summary = summary_of(file);
  file[kMcapMagic.size() + kMcapRecordPrefix + 4] ^= 1;  // the profile's first character
  const std::uint64_t data_end_at = summary.footer.summary_start - kMcapRecordPrefix - 4;
  const std::string error = error_of(file);
  EXPECT_THAT(error, HasSubstr(offset_text(data_end_at)));
  EXPECT_THAT(error, HasSubstr("data section CRC"));
}

TEST(McapDamage, SummaryCrcIsChecked) {
  auto file = write_sample(small_chunks(McapCompression::zstd), 30).written.file;
  const McapSummary summary = summary_of(file);
  file[summary.footer.summary_start + 20] ^= 1;
  EXPECT_THAT(error_of(file), HasSubstr("summary CRC mismatch"));
  auto only = read_mcap_summary(file);
  ASSERT_FALSE(only);
  EXPECT_THAT(only.error().text, HasSubstr(offset_text(summary.footer.summary_start)));
}

TEST(McapDamage, MessageOnAnUndeclaredChannel) {
  std::uint64_t message_at = 0;
  const Bytes data{1, 2};
  const Bytes file = build_file([&](Bytes& f) {
    append_mcap_record(f, McapChannel{1, 0, "known", "x-raw", {}});
    append_mcap_record(f, McapMessageView{1, 0, 5, 5, data});
    message_at = f.size();
    append_mcap_record(f, McapMessageView{7, 0, 6, 6, data});
  });
  const std::string error = error_of(file);
  EXPECT_THAT(error, HasSubstr(offset_text(message_at)));
  EXPECT_THAT(error, HasSubstr("channel 7"));
}

TEST(McapDamage, ChannelOnAnUndeclaredSchemaAndRedefinitions) {
  EXPECT_THAT(error_of(build_file([](Bytes& f) {
                append_mcap_record(f, McapChannel{1, 4, "t", "cdr", {}});
              })),
              HasSubstr("schema 4"));
  EXPECT_THAT(error_of(build_file([](Bytes& f) {
                append_mcap_record(f, McapChannel{1, 0, "t", "cdr", {}});
                append_mcap_record(f, McapChannel{1, 0, "other", "cdr", {}});
              })),
              HasSubstr("redefined"));
  // The same record twice (a writer repeating channels) is fine.
  auto same = read_mcap(build_file([](Bytes& f) {
    append_mcap_record(f, McapChannel{1, 0, "t", "cdr", {}});
    append_mcap_record(f, McapChannel{1, 0, "t", "cdr", {}});
  }));
  ASSERT_TRUE(same);
  EXPECT_EQ(same.value().channels.size(), 1u);
}

// A chunk record holding `records` under `compression`, with the given claimed size.
void append_chunk(Bytes& f, std::string compression, std::span<const std::uint8_t> stored, std::uint64_t claimed,
                  std::uint32_t crc) {
  McapChunkView chunk;
  chunk.uncompressed_size = claimed;
  chunk.uncompressed_crc = crc;
  chunk.compression = std::move(compression);
  chunk.records = stored;
  append_mcap_record(f, chunk);
}

TEST(McapDamage, AChunkClaimingTooMuchIsRefusedBeforeAllocating) {
  const Bytes stored(100, 0);
  for (const std::uint64_t claimed : {std::uint64_t{1} << 40, std::uint64_t{2} << 20 /* 2 MiB from 100 B */}) {
    std::uint64_t chunk_at = 0;
    const Bytes file = build_file([&](Bytes& f) {
      chunk_at = f.size();
      append_chunk(f, "zstd", stored, claimed, 0);
    });
    const std::string error = error_of(file);
    EXPECT_THAT(error, HasSubstr(offset_text(chunk_at)));
    EXPECT_THAT(error, HasSubstr("over the limit"));
  }
  EXPECT_THAT(error_of(build_file([&](Bytes& f) { append_chunk(f, "brotli", stored, 100, 0); })),
              HasSubstr("unsupported compression 'brotli'"));
  EXPECT_THAT(error_of(build_file([&](Bytes& f) { append_chunk(f, "", stored, 99, 0); })),
              HasSubstr("does not decompress"));
}

// Records as a chunk holds them: a channel and two messages.
Bytes inner_records(const Bytes& a, const Bytes& b) {
  Bytes records;
  append_mcap_record(records, McapChannel{3, 0, "lz4/topic", "x-raw", {{"k", "v"}}});
  append_mcap_record(records, McapMessageView{3, 1, 100, 90, a});
  append_mcap_record(records, McapMessageView{3, 2, 200, 190, b});
  return records;
}

TEST(McapReader, ReadsLz4Chunks) {
  const Bytes a(300, 'a');
  const Bytes b = mcap_test::bytes_of("second message");
  const Bytes records = inner_records(a, b);
  Bytes packed(LZ4F_compressFrameBound(records.size(), nullptr));
  const std::size_t n = LZ4F_compressFrame(packed.data(), packed.size(), records.data(), records.size(), nullptr);
  ASSERT_FALSE(LZ4F_isError(n));
  packed.resize(n);
  ASSERT_LT(packed.size(), records.size());
  auto read =
      read_mcap(build_file([&](Bytes& f) { append_chunk(f, "lz4", packed, records.size(), mcap_crc32(records)); }));
  ASSERT_TRUE(read) << read.error().text;
  ASSERT_EQ(read.value().messages.size(), 2u);
  EXPECT_EQ(read.value().messages[0].data, a);
  EXPECT_EQ(read.value().messages[1].data, b);
  EXPECT_EQ(read.value().messages[1].publish_time, 190u);
  EXPECT_EQ(read.value().channels.at(0).topic, "lz4/topic");
  // The frame cut short, or claiming one byte more than it holds, does not decompress.
  const std::span<const std::uint8_t> short_frame = std::span(packed).first(packed.size() - 5);
  EXPECT_THAT(error_of(build_file([&](Bytes& f) { append_chunk(f, "lz4", short_frame, records.size(), 0); })),
              HasSubstr("does not decompress"));
  EXPECT_THAT(error_of(build_file([&](Bytes& f) { append_chunk(f, "lz4", packed, records.size() + 1, 0); })),
              HasSubstr("does not decompress"));
}

// Other writers may put records straight into the data section, without chunks or summary.
TEST(McapReader, ReadsMessagesOutsideChunks) {
  const Bytes a{1}, b{2, 3};
  auto read = read_mcap(build_file([&](Bytes& f) {
    append_mcap_record(f, McapSchema{0, "ignored", "", {}});  // id 0: ignored, as the spec says
    const Bytes records = inner_records(a, b);
    f.insert(f.end(), records.begin(), records.end());
    append_mcap_record(f, McapMetadata{"m", {{"a", "b"}}});
  }));
  ASSERT_TRUE(read) << read.error().text;
  EXPECT_FALSE(read.value().truncated);
  EXPECT_TRUE(read.value().schemas.empty());
  ASSERT_EQ(read.value().messages.size(), 2u);
  EXPECT_EQ(read.value().messages[0].sequence, 1u);
  EXPECT_EQ(read.value().metadata.at(0).metadata.at("a"), "b");
  EXPECT_FALSE(read.value().summary);  // the footer names no summary
}

TEST(McapReader, ScanStopsAtTheCallbacksError) {
  const auto sample = write_sample(small_chunks(McapCompression::zstd), 50);
  int seen = 0;
  auto scan = scan_mcap(sample.written.file, [&](const McapMessageView& m, const McapChannel& c) -> Result<void> {
    EXPECT_EQ(m.channel_id, c.id);
    if (++seen == 7) return Error{"enough"};
    return {};
  });
  ASSERT_FALSE(scan);
  EXPECT_EQ(scan.error().text, "enough");
  EXPECT_EQ(seen, 7);
}

// The summary alone: the reads it makes never touch the data section.
TEST(McapSummaryOnly, ReadsOnlyTheHeaderAndTheEnd) {
  const auto sample = write_sample(small_chunks(McapCompression::zstd, 16384), 3000);
  const Bytes& file = sample.written.file;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> reads;
  const McapReadAt read_at = [&](std::uint64_t offset, std::span<std::uint8_t> out) -> Result<void> {
    reads.emplace_back(offset, out.size());
    std::copy_n(file.begin() + static_cast<std::ptrdiff_t>(offset), out.size(), out.begin());
    return {};
  };
  auto summary = read_mcap_summary(file.size(), read_at);
  ASSERT_TRUE(summary && summary.value());
  const McapSummary& s = *summary.value();
  auto whole = read_mcap(file);
  ASSERT_TRUE(whole && whole.value().summary);
  EXPECT_EQ(s.chunk_indexes, whole.value().summary->chunk_indexes);
  EXPECT_EQ(s.statistics, whole.value().summary->statistics);
  EXPECT_EQ(s.channels, sample.channels);
  EXPECT_EQ(s.header.library, "cosmic-gateway");
  ASSERT_TRUE(s.statistics);
  EXPECT_EQ(s.statistics->message_count, 3000u);
  const std::uint64_t data_begin = s.chunk_indexes.front().chunk_start_offset;
  std::uint64_t bytes_read = 0;
  for (const auto& [offset, size] : reads) {
    EXPECT_TRUE(offset + size <= data_begin || offset >= s.footer.summary_start) << offset << "+" << size;
    bytes_read += size;
  }
  EXPECT_LT(bytes_read, file.size() / 10);
}

TEST(McapSummaryOnly, AFileWithoutSummaryHasNone) {
  auto summary = read_mcap_summary(build_file([](Bytes&) {}));
  ASSERT_TRUE(summary) << summary.error().text;
  EXPECT_FALSE(summary.value().has_value());
  EXPECT_THAT(read_mcap_summary(Bytes(10, 0)).error().text, HasSubstr("too short"));
}

TEST(McapSummaryOnly, AFooterPointingOutsideTheFileIsAnError) {
  Bytes file = build_file([](Bytes&) {});
  const std::uint64_t footer_at = file.size() - kMcapFooterTail;
  file[footer_at + kMcapRecordPrefix + 7] = 0x10;  // summary_start's top byte
  auto summary = read_mcap_summary(file);
  ASSERT_FALSE(summary);
  EXPECT_THAT(summary.error().text, HasSubstr(offset_text(footer_at)));
  EXPECT_THAT(error_of(file), HasSubstr(offset_text(footer_at)));
}

}  // namespace
}  // namespace cosmic

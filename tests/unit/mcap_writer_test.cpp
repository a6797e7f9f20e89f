// McapWriter (cosmic/mcap_writer.hpp): round trips through the reader with zstd and without
// compression, chunks closed at chunk_size and given to the sink whole, schemas and channels in
// the chunk of their first message, the summary's statistics, chunk indexes, message indexes and
// summary offsets checked against the bytes they point at, and the calls it refuses.
#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <set>
#include <string>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_records.hpp"
#include "cosmic/mcap_writer.hpp"
#include "mcap_test_support.hpp"

namespace cosmic {
namespace {

using mcap_test::Bytes;
using mcap_test::small_chunks;
using mcap_test::write_sample;

class McapWriterRoundTrip : public testing::TestWithParam<McapCompression> {};

TEST_P(McapWriterRoundTrip, ReadsBackWhatWasWritten) {
  const auto sample = write_sample(small_chunks(GetParam(), 2048), 500);
  auto read = read_mcap(sample.written.file);
  ASSERT_TRUE(read) << read.error().text;
  const McapFile& f = read.value();
  EXPECT_FALSE(f.truncated) << f.truncation;
  EXPECT_EQ(f.header, (McapHeader{"x-cosmic", "cosmic-gateway"}));
  EXPECT_EQ(f.schemas, sample.schemas);
  EXPECT_EQ(f.channels, sample.channels);
  EXPECT_EQ(f.messages, sample.messages);
  ASSERT_EQ(f.metadata.size(), 1u);
  EXPECT_EQ(f.metadata[0], sample.metadata);
  ASSERT_TRUE(f.summary.has_value());
  EXPECT_EQ(f.summary->schemas, sample.schemas);
  EXPECT_EQ(f.summary->channels, sample.channels);
  ASSERT_EQ(f.summary->metadata_indexes.size(), 1u);
  EXPECT_EQ(f.summary->metadata_indexes[0].name, "gateway");
  EXPECT_EQ(f.complete_bytes, sample.written.file.size());
}

TEST_P(McapWriterRoundTrip, CountersMatchTheFile) {
  const auto sample = write_sample(small_chunks(GetParam(), 4096), 2000);
  auto summary = read_mcap_summary(sample.written.file);
  ASSERT_TRUE(summary && summary.value()) << (summary ? "no summary" : summary.error().text);
  std::uint64_t compressed = 0;
  std::uint64_t uncompressed = 0;
  for (const McapChunkIndex& c : summary.value()->chunk_indexes) {
    compressed += c.compressed_size;
    uncompressed += c.uncompressed_size;
  }
  // The same writer's counters, recomputed: write the same file again and ask before finishing.
  mcap_test::Written again;
  auto writer = McapWriter::open(small_chunks(GetParam(), 4096), mcap_test::sink_into(again));
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  for (const McapSchema& s : sample.schemas) ASSERT_TRUE(w.add_schema(s.name, s.encoding, s.data));
  for (const McapChannel& c : sample.channels)
    ASSERT_TRUE(w.add_channel(c.schema_id, c.topic, c.message_encoding, c.metadata));
  for (std::size_t i = 0; i < sample.messages.size(); ++i) {
    if (i == sample.messages.size() / 3) {
      ASSERT_TRUE(w.add_metadata(sample.metadata.name, sample.metadata.metadata));
    }
    const McapMessage& m = sample.messages[i];
    ASSERT_TRUE(w.write_message(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data));
  }
  ASSERT_TRUE(w.finish());
  EXPECT_EQ(again.file, sample.written.file);  // deterministic: same calls, same bytes
  EXPECT_EQ(w.bytes_written(), sample.written.file.size());
  EXPECT_EQ(w.message_count(), 2000u);
  EXPECT_EQ(w.compressed_bytes(), compressed);
  EXPECT_EQ(w.uncompressed_bytes(), uncompressed);
  if (GetParam() == McapCompression::zstd) {
    EXPECT_LT(compressed, uncompressed / 2);  // the sample's bytes repeat a lot
  } else {
    EXPECT_EQ(compressed, uncompressed);
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapWriterRoundTrip,
                         testing::Values(McapCompression::zstd, McapCompression::none),
                         [](const auto& info) { return info.param == McapCompression::zstd ? "zstd" : "none"; });

// The chunk's records as the file holds them, decompressed.
Bytes chunk_records(const McapChunkView& chunk) {
  if (chunk.compression.empty()) return Bytes(chunk.records.begin(), chunk.records.end());
  Bytes out(chunk.uncompressed_size);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), chunk.records.data(), chunk.records.size());
  EXPECT_EQ(n, out.size());
  return out;
}

class McapWriterIndexes : public testing::TestWithParam<McapCompression> {};

// Every Chunk Index points at its chunk, every Message Index entry at its message.
TEST_P(McapWriterIndexes, ChunkAndMessageIndexesPointAtTheirRecords) {
  const auto sample = write_sample(small_chunks(GetParam(), 300), 400);
  const Bytes& file = sample.written.file;
  auto summary = read_mcap_summary(file);
  ASSERT_TRUE(summary && summary.value());
  const auto& indexes = summary.value()->chunk_indexes;
  ASSERT_GT(indexes.size(), 20u);
  std::uint64_t indexed_messages = 0;
  std::multiset<std::uint64_t> indexed_times;
  for (const McapChunkIndex& index : indexes) {
    const McapRecordAt at = mcap_record_at(file, index.chunk_start_offset);
    ASSERT_FALSE(at.incomplete);
    ASSERT_EQ(at.record.opcode, static_cast<std::uint8_t>(McapOpcode::chunk));
    EXPECT_EQ(at.record.length(), index.chunk_length);
    auto chunk = parse_mcap_chunk(at.record.content);
    ASSERT_TRUE(chunk);
    EXPECT_EQ(chunk.value().compression, index.compression);
    EXPECT_EQ(chunk.value().records.size(), index.compressed_size);
    EXPECT_EQ(chunk.value().uncompressed_size, index.uncompressed_size);
    EXPECT_EQ(chunk.value().message_start_time, index.message_start_time);
    EXPECT_EQ(chunk.value().message_end_time, index.message_end_time);
    EXPECT_NE(chunk.value().uncompressed_crc, 0u);
    const Bytes records = chunk_records(chunk.value());
    EXPECT_EQ(mcap_crc32(records), chunk.value().uncompressed_crc);

    // The Message Index records follow the chunk, one per channel, exactly message_index_length long.
    std::uint64_t index_bytes = 0;
    std::uint64_t start = ~std::uint64_t{0};
    std::uint64_t end = 0;
    for (const auto& [channel_id, offset] : index.message_index_offsets) {
      const McapRecordAt mi = mcap_record_at(file, offset);
      ASSERT_EQ(mi.record.opcode, static_cast<std::uint8_t>(McapOpcode::message_index));
      index_bytes += mi.record.length();
      auto parsed = parse_mcap_message_index(mi.record.content);
      ASSERT_TRUE(parsed);
      EXPECT_EQ(parsed.value().channel_id, channel_id);
      for (const auto& [log_time, in_chunk] : parsed.value().entries) {
        const McapRecordAt m = mcap_record_at(records, in_chunk);
        ASSERT_EQ(m.record.opcode, static_cast<std::uint8_t>(McapOpcode::message));
        auto message = parse_mcap_message(m.record.content);
        ASSERT_TRUE(message);
        EXPECT_EQ(message.value().channel_id, channel_id);
        EXPECT_EQ(message.value().log_time, log_time);
        start = std::min(start, log_time);
        end = std::max(end, log_time);
        indexed_times.insert(log_time);
        ++indexed_messages;
      }
    }
    EXPECT_EQ(index_bytes, index.message_index_length);
    EXPECT_EQ(index.message_index_offsets.begin()->second, index.chunk_start_offset + index.chunk_length);
    EXPECT_EQ(start, index.message_start_time);
    EXPECT_EQ(end, index.message_end_time);
  }
  EXPECT_EQ(indexed_messages, sample.messages.size());
  std::multiset<std::uint64_t> written_times;
  for (const McapMessage& m : sample.messages) written_times.insert(m.log_time);
  EXPECT_EQ(indexed_times, written_times);
}

TEST_P(McapWriterIndexes, StatisticsCountEveryChannel) {
  const auto sample = write_sample(small_chunks(GetParam(), 300), 400);
  auto summary = read_mcap_summary(sample.written.file);
  ASSERT_TRUE(summary && summary.value());
  ASSERT_TRUE(summary.value()->statistics);
  const McapStatistics& s = *summary.value()->statistics;
  EXPECT_EQ(s.message_count, 400u);
  EXPECT_EQ(s.schema_count, 2u);
  EXPECT_EQ(s.channel_count, 3u);
  EXPECT_EQ(s.metadata_count, 1u);
  EXPECT_EQ(s.attachment_count, 0u);
  EXPECT_EQ(s.chunk_count, summary.value()->chunk_indexes.size());
  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t first = ~std::uint64_t{0};
  std::uint64_t last = 0;
  for (const McapMessage& m : sample.messages) {
    ++counts[m.channel_id];
    first = std::min(first, m.log_time);
    last = std::max(last, m.log_time);
  }
  EXPECT_EQ(s.channel_message_counts, counts);
  EXPECT_EQ(s.message_start_time, first);
  EXPECT_EQ(s.message_end_time, last);
  EXPECT_LT(first, sample.messages[0].log_time);  // the sample's earliest message is not its first
}

// Each Summary Offset names the group of its opcode; the Footer's and Data End's CRCs are the
// CRCs of the bytes they cover.
TEST_P(McapWriterIndexes, SummaryOffsetsAndCrcsCoverTheirBytes) {
  const auto sample = write_sample(small_chunks(GetParam(), 300), 100);
  const Bytes& file = sample.written.file;
  auto summary = read_mcap_summary(file);
  ASSERT_TRUE(summary && summary.value());
  const McapSummary& s = *summary.value();
  std::set<std::uint8_t> groups;
  for (const McapSummaryOffset& offset : s.summary_offsets) {
    groups.insert(offset.group_opcode);
    std::uint64_t at = offset.group_start;
    while (at < offset.group_start + offset.group_length) {
      const McapRecordAt r = mcap_record_at(file, at);
      ASSERT_FALSE(r.incomplete);
      EXPECT_EQ(r.record.opcode, offset.group_opcode);
      at += r.record.length();
    }
    EXPECT_EQ(at, offset.group_start + offset.group_length);
  }
  EXPECT_EQ(groups, (std::set<std::uint8_t>{0x03, 0x04, 0x08, 0x0B, 0x0D}));
  const std::uint64_t footer_at = file.size() - kMcapFooterTail;
  EXPECT_EQ(mcap_crc32(std::span(file).subspan(s.footer.summary_start, footer_at + 9 + 16 - s.footer.summary_start)),
            s.footer.summary_crc);
  // Data End sits right before the summary; its CRC covers everything before it.
  const std::uint64_t data_end_at = s.footer.summary_start - kMcapRecordPrefix - 4;
  const McapRecordAt data_end = mcap_record_at(file, data_end_at);
  ASSERT_EQ(data_end.record.opcode, static_cast<std::uint8_t>(McapOpcode::data_end));
  EXPECT_EQ(parse_mcap_data_end(data_end.record.content).value().data_section_crc,
            mcap_crc32(std::span(file).first(data_end_at)));
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapWriterIndexes, testing::Values(McapCompression::zstd, McapCompression::none),
                         [](const auto& info) { return info.param == McapCompression::zstd ? "zstd" : "none"; });

// Chunks close once their records reach chunk_size, and each reaches the sink in one call.
TEST(McapWriter, ChunksCloseAtChunkSizeAndReachTheSinkWhole) {
  constexpr std::uint64_t kChunkSize = 500;
  const auto sample = write_sample(small_chunks(McapCompression::none, kChunkSize), 300);
  auto summary = read_mcap_summary(sample.written.file);
  ASSERT_TRUE(summary && summary.value());
  const auto& indexes = summary.value()->chunk_indexes;
  ASSERT_GT(indexes.size(), 10u);
  const auto& calls = sample.written.call_offsets;
  for (std::size_t i = 0; i < indexes.size(); ++i) {
    // Over chunk_size by less than one record (the largest: a 61-byte message plus 31 bytes of
    // fields and prefix, or the channel's declarations with it); only the last may be smaller.
    if (i + 1 < indexes.size()) {
      EXPECT_GE(indexes[i].uncompressed_size, kChunkSize);
      EXPECT_LT(indexes[i].uncompressed_size, kChunkSize + 300);
    }
    EXPECT_TRUE(std::find(calls.begin(), calls.end(), indexes[i].chunk_start_offset) != calls.end())
        << "chunk " << i << " does not start a sink call";
  }
  // Nothing reaches the sink before a chunk fills: the first call is the magic and header alone.
  ASSERT_GE(calls.size(), 2u);
  EXPECT_EQ(calls[1], indexes[0].chunk_start_offset);
}

// A channel's Schema and Channel records go into the chunk of its first message: the file cut
// after the first chunk names only the channels that chunk uses.
TEST(McapWriter, DeclaresAChannelInTheChunkOfItsFirstMessage) {
  mcap_test::Written out;
  auto writer = McapWriter::open(small_chunks(McapCompression::zstd, 1 << 20), mcap_test::sink_into(out));
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  const auto schema = w.add_schema("A", "jsonschema", mcap_test::bytes_of("{}"));
  ASSERT_TRUE(schema);
  const auto first = w.add_channel(schema.value(), "first", "json");
  const auto later = w.add_channel(0, "later", "x-raw");
  ASSERT_TRUE(first && later);
  const Bytes data = mcap_test::bytes_of("{}");
  ASSERT_TRUE(w.write_message(first.value(), 0, 10, 10, data));
  ASSERT_TRUE(w.flush_chunk());
  const std::uint64_t first_chunk_end = w.bytes_written();
  EXPECT_GT(first_chunk_end, out.call_offsets[1]);  // flush_chunk gave the sink the chunk
  ASSERT_TRUE(w.write_message(later.value(), 0, 20, 20, data));
  ASSERT_TRUE(w.finish());

  auto cut = read_mcap(std::span(out.file).first(first_chunk_end));
  ASSERT_TRUE(cut) << cut.error().text;
  EXPECT_TRUE(cut.value().truncated);
  ASSERT_EQ(cut.value().channels.size(), 1u);
  EXPECT_EQ(cut.value().channels[0].topic, "first");
  EXPECT_EQ(cut.value().schemas.size(), 1u);
  EXPECT_EQ(cut.value().messages.size(), 1u);
  auto whole = read_mcap(out.file);
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole.value().channels.size(), 2u);
  EXPECT_EQ(whole.value().messages.size(), 2u);
}

TEST(McapWriter, AnEmptyFileIsValid) {
  mcap_test::Written out;
  auto writer = McapWriter::open({}, mcap_test::sink_into(out));
  ASSERT_TRUE(writer);
  ASSERT_TRUE(writer.value().flush_chunk());  // nothing open: nothing written
  ASSERT_TRUE(writer.value().finish());
  auto read = read_mcap(out.file);
  ASSERT_TRUE(read) << read.error().text;
  EXPECT_FALSE(read.value().truncated);
  EXPECT_TRUE(read.value().messages.empty());
  ASSERT_TRUE(read.value().summary && read.value().summary->statistics);
  EXPECT_EQ(read.value().summary->statistics->message_count, 0u);
  EXPECT_EQ(read.value().summary->statistics->message_start_time, 0u);
  EXPECT_TRUE(read.value().summary->chunk_indexes.empty());
}

TEST(McapWriter, RefusesUnknownIdsAndCallsAfterFinish) {
  mcap_test::Written out;
  auto writer = McapWriter::open({}, mcap_test::sink_into(out));
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  const Bytes data{1, 2, 3};
  EXPECT_FALSE(w.add_channel(1, "t", "cdr"));  // schema 1 was not added
  const auto channel = w.add_channel(0, "t", "x-raw");
  ASSERT_TRUE(channel);
  EXPECT_FALSE(w.write_message(0, 0, 1, 1, data));
  EXPECT_FALSE(w.write_message(channel.value() + 1, 0, 1, 1, data));
  ASSERT_TRUE(w.write_message(channel.value(), 0, 1, 1, data));
  ASSERT_TRUE(w.finish());
  const std::size_t size = out.file.size();
  EXPECT_FALSE(w.write_message(channel.value(), 1, 2, 2, data));
  EXPECT_FALSE(w.finish());
  EXPECT_FALSE(w.add_metadata("m", {}));
  EXPECT_EQ(out.file.size(), size);  // nothing after the closing magic
  EXPECT_FALSE(McapWriter::open({}, McapSink{}));
}

TEST(McapWriter, ASinkFailureStopsTheWriter) {
  int calls = 0;
  const McapSink failing = [&calls](std::span<const std::uint8_t>) -> Result<void> {
    if (++calls == 2) return Error{"disk full", 28};
    return {};
  };
  auto writer = McapWriter::open(small_chunks(McapCompression::zstd, 64), failing);
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  const auto channel = w.add_channel(0, "t", "x-raw");
  ASSERT_TRUE(channel);
  const Bytes data(100, 7);
  const auto failed = w.write_message(channel.value(), 0, 1, 1, data);  // closes a chunk: call 2
  ASSERT_FALSE(failed);
  EXPECT_EQ(failed.error().code, 28);
  EXPECT_NE(failed.error().text.find("disk full"), std::string::npos);
  EXPECT_FALSE(w.write_message(channel.value(), 1, 2, 2, data));
  EXPECT_FALSE(w.finish());
  EXPECT_EQ(calls, 2);  // refused without touching the sink again
}

// What a failed flush loses: the open chunk's messages, which the writer still reports (the
// recorder counts them as not written), while every message of a chunk the sink took is gone from
// that count.
TEST(McapWriter, ReportsTheMessagesOfTheChunkItCouldNotWrite) {
  bool refuse = false;
  const McapSink sink = [&refuse](std::span<const std::uint8_t>) -> Result<void> {
    if (refuse) return Error{"disk full", 28};
    return {};
  };
  auto writer = McapWriter::open(small_chunks(McapCompression::zstd, 1 << 20), sink);
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  const auto channel = w.add_channel(0, "t", "x-raw");
  ASSERT_TRUE(channel);
  const Bytes data(100, 7);
  for (std::uint32_t n = 0; n < 3; ++n) ASSERT_TRUE(w.write_message(channel.value(), n, n, n, data));
  EXPECT_EQ(w.chunk_message_count(), 3u);
  ASSERT_TRUE(w.flush_chunk());
  EXPECT_EQ(w.chunk_message_count(), 0u);  // with the sink
  for (std::uint32_t n = 3; n < 8; ++n) ASSERT_TRUE(w.write_message(channel.value(), n, n, n, data));
  refuse = true;
  EXPECT_FALSE(w.flush_chunk());
  EXPECT_EQ(w.message_count(), 8u);
  EXPECT_EQ(w.chunk_message_count(), 5u);  // never reached the sink
  EXPECT_FALSE(w.finish());
  EXPECT_EQ(w.chunk_message_count(), 5u);
}

}  // namespace
}  // namespace cosmic

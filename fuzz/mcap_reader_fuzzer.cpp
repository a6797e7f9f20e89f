// An MCAP file as `cosmicctl record info` and replay will read one (issue 37): the whole input
// through read_mcap, and through read_mcap_summary, the summary-only path.
// Checked beyond "no crash": an error names its offset ("mcap offset N: ..."); a file read has its
// messages on declared channels, a truncated one says why and its complete part lies within the
// input; where read_mcap finds a summary, read_mcap_summary finds the same one; the messages
// written again by McapWriter (both compressions) read back the same, on channels of the same
// topics.
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_writer.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

bool names_offset(const cosmic::Error& error) { return error.text.rfind("mcap offset ", 0) == 0; }

// The file's schemas, channels and messages through McapWriter, read back.
void write_again(const cosmic::McapFile& f, cosmic::McapCompression compression) {
  std::vector<std::uint8_t> out;
  cosmic::McapWriterOptions options;
  options.compression = compression;
  options.chunk_size = 256;  // several chunks from small inputs
  auto opened = cosmic::McapWriter::open(options, [&out](std::span<const std::uint8_t> bytes) -> cosmic::Result<void> {
    out.insert(out.end(), bytes.begin(), bytes.end());
    return {};
  });
  require(opened.ok());
  cosmic::McapWriter& w = opened.value();
  std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;  // file's id -> writer's
  for (const auto& s : f.schemas) schema_ids[s.id] = w.add_schema(s.name, s.encoding, s.data).value();
  for (const auto& c : f.channels) {
    const std::uint16_t schema = c.schema_id == 0 ? 0 : schema_ids.at(c.schema_id);
    channel_ids[c.id] = w.add_channel(schema, c.topic, c.message_encoding, c.metadata).value();
  }
  for (const auto& m : f.messages)
    require(w.write_message(channel_ids.at(m.channel_id), m.sequence, m.log_time, m.publish_time, m.data).ok());
  require(w.finish().ok());

  auto again = cosmic::read_mcap(out);
  require(again.ok() && !again.value().truncated && again.value().summary.has_value());
  const auto& messages = again.value().messages;
  require(messages.size() == f.messages.size());
  std::map<std::uint16_t, std::string> topics;
  for (const auto& c : again.value().channels) topics[c.id] = c.topic;
  std::map<std::uint16_t, std::string> original_topics;
  for (const auto& c : f.channels) original_topics[c.id] = c.topic;
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const auto& a = messages[i];
    const auto& b = f.messages[i];
    require(a.sequence == b.sequence && a.log_time == b.log_time && a.publish_time == b.publish_time &&
            a.data == b.data && topics.at(a.channel_id) == original_topics.at(b.channel_id));
  }
  require(again.value().summary->statistics->message_count == f.messages.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  auto read = cosmic::read_mcap(input);
  auto summary = cosmic::read_mcap_summary(input);
  if (!summary) require(names_offset(summary.error()));
  if (!read) {
    require(names_offset(read.error()));
    return 0;
  }
  const cosmic::McapFile& f = read.value();
  require(f.complete_bytes <= size);
  require(f.truncated == !f.truncation.empty());
  require(f.message_count == f.messages.size());
  std::map<std::uint16_t, bool> declared;
  for (const auto& c : f.channels) declared[c.id] = true;
  for (const auto& m : f.messages) require(declared.contains(m.channel_id));
  if (f.summary) {
    require(summary.ok() && summary.value().has_value());
    const cosmic::McapSummary& s = *summary.value();
    require(s.chunk_indexes == f.summary->chunk_indexes && s.channels == f.summary->channels &&
            s.statistics == f.summary->statistics && s.footer == f.summary->footer);
  }
  if (f.messages.size() <= 2000) {
    write_again(f, cosmic::McapCompression::none);
    write_again(f, cosmic::McapCompression::zstd);
  }
  return 0;
}

// Deterministic MCAP files for the cosmic_mcap tests: a sample written by McapWriter (two schemas,
// three channels, one without a schema, metadata), and files built record by record for what
// McapWriter never writes (messages outside chunks, lz4 chunks, damage).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_records.hpp"
#include "cosmic/mcap_writer.hpp"

namespace cosmic::mcap_test {

using Bytes = std::vector<std::uint8_t>;

inline Bytes bytes_of(std::string_view text) { return Bytes(text.begin(), text.end()); }

// What the sink received, call by call.
struct Written {
  Bytes file;
  std::vector<std::uint64_t> call_offsets;  // where each sink call began
};

inline McapSink sink_into(Written& w) {
  return [&w](std::span<const std::uint8_t> bytes) -> Result<void> {
    w.call_offsets.push_back(w.file.size());
    w.file.insert(w.file.end(), bytes.begin(), bytes.end());
    return {};
  };
}

// Message i of the sample: on channel 1..3 in turn, log times mostly rising but not always (a
// recorder sees events out of order across channels), sizes 1..61 bytes.
inline McapMessage sample_message(std::uint32_t i) {
  McapMessage m;
  m.channel_id = static_cast<std::uint16_t>(i % 3 + 1);
  m.sequence = i / 3;
  m.log_time = 1'000'000 + std::uint64_t{i} * 1'000 - (i % 4 == 1 ? 1'500 : 0);
  m.publish_time = m.log_time - 250;
  m.data.resize(1 + (i * 7) % 61);
  for (std::size_t k = 0; k < m.data.size(); ++k) m.data[k] = static_cast<std::uint8_t>(i * 31 + k);
  return m;
}

struct Sample {
  Written written;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::vector<McapMessage> messages;
  McapMetadata metadata{"gateway", {{"config", "robot.yaml"}, {"version", "0.1.0"}}};
};

// The sample file: `count` messages, a metadata record after the first third.
inline Sample write_sample(McapWriterOptions options, std::uint32_t count) {
  Sample s;
  auto writer = McapWriter::open(std::move(options), sink_into(s.written));
  if (!writer) return s;
  McapWriter& w = writer.value();
  s.schemas.push_back({1, "cosmic_msgs/msg/Distance", "ros2msg", bytes_of("float32 meters\nuint8 quality\n")});
  s.schemas.push_back(
      {2, "Speed", "jsonschema", bytes_of(R"({"type":"object","properties":{"v":{"type":"number"}}})")});
  s.channels.push_back({1, 1, "distance", "cdr", {{"segment", "body-can"}, {"origin", "7"}}});
  s.channels.push_back({2, 2, "speed", "json", {}});
  s.channels.push_back({3, 0, "raw/opaque", "x-cosmic-raw", {{"subject", "0x42"}}});
  for (const McapSchema& schema : s.schemas) (void)w.add_schema(schema.name, schema.encoding, schema.data);
  for (const McapChannel& c : s.channels) (void)w.add_channel(c.schema_id, c.topic, c.message_encoding, c.metadata);
  for (std::uint32_t i = 0; i < count; ++i) {
    if (i == count / 3) (void)w.add_metadata(s.metadata.name, s.metadata.metadata);
    s.messages.push_back(sample_message(i));
    const McapMessage& m = s.messages.back();
    (void)w.write_message(m.channel_id, m.sequence, m.log_time, m.publish_time, m.data);
  }
  (void)w.finish();
  return s;
}

inline McapWriterOptions small_chunks(McapCompression compression, std::uint64_t chunk_size = 300) {
  McapWriterOptions o;
  o.compression = compression;
  o.chunk_size = chunk_size;
  return o;
}

// A file built record by record: magic, header, what `body` appends, then Data End, Footer (no
// summary) and magic.
template <typename Body>
Bytes build_file(Body body) {
  Bytes f(kMcapMagic.begin(), kMcapMagic.end());
  append_mcap_record(f, McapHeader{"", "hand"});
  body(f);
  append_mcap_record(f, McapDataEnd{0});
  append_mcap_record(f, McapFooter{});
  f.insert(f.end(), kMcapMagic.begin(), kMcapMagic.end());
  return f;
}

// The messages of `file` as read_mcap reads them (empty when it fails).
inline std::vector<McapMessage> messages_of(std::span<const std::uint8_t> file) {
  auto read = read_mcap(file);
  return read ? read.value().messages : std::vector<McapMessage>{};
}

}  // namespace cosmic::mcap_test

// What a recording holds (cosmic/recording_info.hpp).
#include "cosmic/recording_info.hpp"

#include <map>

#include "cosmic/mcap_reader.hpp"

namespace cosmic {
namespace {

std::string value_of(const McapMap& map, const std::string& key) {
  const auto it = map.find(key);
  return it == map.end() ? std::string() : it->second;
}

// Per stream, what the scan needs besides its figures: the last sequence number seen.
struct StreamState {
  std::size_t index = 0;
  bool any = false;
  std::uint32_t last_sequence = 0;
};

void count(RecordedStream& stream, StreamState& state, const McapMessageView& message) {
  const std::uint64_t at = message.log_time;
  if (stream.messages == 0) {
    stream.first_ns = at;
  } else if (at > stream.last_ns) {
    stream.largest_gap_ns = std::max(stream.largest_gap_ns, at - stream.last_ns);
  }
  stream.last_ns = std::max(stream.last_ns, at);
  ++stream.messages;
  stream.bytes += message.data.size();
  if (state.any && message.sequence > state.last_sequence) stream.missing += message.sequence - state.last_sequence - 1;
  if (!state.any || message.sequence > state.last_sequence) state.last_sequence = message.sequence;
  state.any = true;
}

}  // namespace

double RecordedStream::rate_hz() const {
  if (messages < 2 || last_ns <= first_ns) return 0;
  return static_cast<double>(messages - 1) * 1e9 / static_cast<double>(last_ns - first_ns);
}

Result<RecordingInfo> recording_info(std::span<const std::uint8_t> file) {
  RecordingInfo info;
  std::map<std::uint16_t, StreamState> streams;
  const auto on_message = [&](const McapMessageView& message, const McapChannel& channel) -> Result<void> {
    auto [it, added] = streams.try_emplace(channel.id);
    if (added) {
      it->second.index = info.streams.size();
      info.streams.push_back({channel.topic, value_of(channel.metadata, "segment"),
                              value_of(channel.metadata, "origin"), channel.message_encoding});
    }
    count(info.streams[it->second.index], it->second, message);
    const std::uint64_t at = message.log_time;
    info.start_ns = info.messages == 0 ? at : std::min(info.start_ns, at);
    info.end_ns = std::max(info.end_ns, at);
    ++info.messages;
    return {};
  };
  auto scanned = scan_mcap(file, on_message);
  if (!scanned) return std::move(scanned).error();
  const McapScan& scan = scanned.value();
  info.profile = scan.header.profile;
  info.library = scan.header.library;
  info.whole = !scan.truncated && scan.summary.has_value();
  info.truncation = scan.truncation;
  info.chunks = scan.chunk_count;
  for (const McapMetadata& m : scan.metadata) {
    if (m.name == "cosmic") info.gateway = value_of(m.metadata, "gateway");
    if (m.name == "cosmic.closing") info.closing = m.metadata;
  }
  if (scan.summary) {
    for (const McapChunkIndex& chunk : scan.summary->chunk_indexes) {
      info.compressed_bytes += chunk.compressed_size;
      info.uncompressed_bytes += chunk.uncompressed_size;
    }
  }
  return info;
}

}  // namespace cosmic

// A replay segment (replay_loader.hpp).
#include "replay_loader.hpp"

#include <filesystem>
#include <map>

#include "cosmic/mapped_file.hpp"
#include "cosmic/mcap_reader.hpp"

namespace cosmic::config_detail {
namespace {

constexpr double kMinSpeed = 0.001;
constexpr double kMaxSpeed = 1000;

std::uint64_t fnv1a(std::span<const std::uint8_t> bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ull;
  for (const std::uint8_t b : bytes) hash = (hash ^ b) * 0x100000001b3ull;
  return hash;
}

// Per selected channel (an MCAP topic): its events and the tightest spacing of two in log time;
// and the selection's span (its first and last log times).
struct Selection {
  std::vector<ReplayStream> streams;
  std::uint64_t first = 0;
  std::uint64_t last = 0;
};

Result<Selection> streams_of(std::span<const std::uint8_t> file, const ReplaySegmentProperties& replay) {
  Selection selection;
  std::vector<ReplayStream>& out = selection.streams;
  std::map<std::string, std::pair<std::size_t, std::uint64_t>> seen;  // topic -> (index, last log time)
  const auto on_message = [&](const McapMessageView& m, const McapChannel& channel) -> Result<void> {
    if (!replay.selects(channel.topic)) return {};
    selection.first = out.empty() ? m.log_time : std::min(selection.first, m.log_time);
    selection.last = std::max(selection.last, m.log_time);
    auto [it, added] = seen.try_emplace(channel.topic, out.size(), m.log_time);
    if (added) {
      out.push_back({channel.topic, 0, Nanos(0)});
    } else if (m.log_time >= it->second.second) {
      const Nanos gap(static_cast<std::int64_t>(m.log_time - it->second.second));
      ReplayStream& stream = out[it->second.first];
      stream.tightest = stream.events < 2 ? gap : std::min(stream.tightest, gap);
    }
    it->second.second = std::max(it->second.second, m.log_time);
    ++out[it->second.first].events;
    return {};
  };
  auto scanned = scan_mcap(file, on_message);
  if (!scanned) return std::move(scanned).error();
  return selection;
}

void parse_options(YamlReader& reader, const YAML::Node& node, const std::string& path, ReplaySegmentProperties& r) {
  if (has(node, "channels") && reader.is_list(node["channels"], key(path, "channels"))) {
    for (std::size_t i = 0; i < node["channels"].size(); ++i) {
      if (auto v = reader.string(node["channels"][i], indexed(key(path, "channels"), i))) r.channels.push_back(*v);
    }
  }
  if (has(node, "speed")) {
    if (auto v = reader.number(node["speed"], key(path, "speed"))) {
      if (*v < kMinSpeed || *v > kMaxSpeed) {
        reader.error_at(node["speed"], key(path, "speed"), "speed out of range",
                        "from 0.001 to 1000: 1 as recorded, 2 twice as fast");
      } else {
        r.speed = *v;
      }
    }
  }
  if (has(node, "loop")) {
    if (auto v = reader.boolean(node["loop"], key(path, "loop"))) r.loop = *v;
  }
  if (has(node, "start_offset")) {
    if (auto v = reader.duration(node["start_offset"], key(path, "start_offset"), true)) r.start_offset = *v;
  }
}

}  // namespace

void parse_replay(YamlReader& reader, const YAML::Node& node, const std::string& path, SegmentSpec& segment,
                  std::vector<std::string>& included) {
  reader.check_map(node, path,
                   {"name", "type", "file", "channels", "speed", "loop", "start_offset", "latency_bound", "realtime",
                    "max_utilization"});
  // A source in this process: what the timer adds to the recorded spacing, at worst.
  segment.latency_bound = Nanos(1'000'000);
  // Declared, as for an IP segment: the replay thread then runs with the receive threads' policy
  // (gateway.realtime), so the gateway's real-time set-up is what keeps the bound; its lateness
  // figures show whether it did.
  segment.realtime = false;
  if (has(node, "realtime")) {
    if (auto v = reader.boolean(node["realtime"], key(path, "realtime"))) segment.realtime = *v;
  }
  if (has(node, "latency_bound")) {
    if (auto v = reader.duration(node["latency_bound"], key(path, "latency_bound"), false)) segment.latency_bound = *v;
  }
  ReplaySegmentProperties& r = segment.replay;
  parse_options(reader, node, path, r);
  if (!has(node, "file")) {
    reader.error_at(node, key(path, "file"), "missing required key 'file'", "an MCAP file cosmicd recorded");
    return;
  }
  const auto text = reader.string(node["file"], key(path, "file"));
  if (!text) return;
  const std::filesystem::path given(*text);
  r.file = given.is_absolute()
               ? given.lexically_normal().string()
               : (std::filesystem::absolute(reader.file()).parent_path() / given).lexically_normal().string();
  included.push_back(r.file);
  const auto mapped = MappedFile::open(r.file);
  if (!mapped) {
    reader.error_at(node["file"], key(path, "file"), mapped.error().text, "an MCAP file cosmicd recorded");
    return;
  }
  auto streams = streams_of(mapped.value()->bytes(), r);
  if (!streams) {
    reader.error_at(node["file"], key(path, "file"), r.file + " is not a readable recording: " + streams.error().text,
                    "an MCAP file cosmicd recorded");
    return;
  }
  if (streams.value().streams.empty()) {
    reader.error_at(node["file"], key(path, "file"),
                    r.file + " holds no event of " + (r.channels.empty() ? "any channel" : "the selected channels"),
                    "a recording of the channels the segment publishes");
    return;
  }
  const Selection& selection = streams.value();
  const std::uint64_t span = selection.last - selection.first;
  if (static_cast<std::uint64_t>(r.start_offset.count()) > span && has(node, "start_offset")) {
    reader.error_at(node["start_offset"], key(path, "start_offset"), "start_offset beyond the recording",
                    "at most " + format_duration(Nanos(static_cast<std::int64_t>(span))) +
                        ", the span of the selected channels' events");
    return;
  }
  r.streams = selection.streams;
  r.content_hash = fnv1a(mapped.value()->bytes());
}

}  // namespace cosmic::config_detail

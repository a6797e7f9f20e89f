// The `recording:` section (recording_loader.hpp).
#include "recording_loader.hpp"

#include <filesystem>

namespace cosmic::config_detail {
namespace {

constexpr std::uint64_t kKiB = 1024;
constexpr std::uint64_t kMiB = 1024 * kKiB;
constexpr std::uint64_t kGiB = 1024 * kMiB;
// Below 4 KiB a chunk's index and header outweigh its messages; above 64 MiB a crash loses too much
// and a reader needs that much memory for one chunk.
constexpr std::uint64_t kMinChunk = 4 * kKiB;
constexpr std::uint64_t kMaxChunk = 64 * kMiB;
constexpr std::uint64_t kMaxRotateSize = 1024 * kGiB;
constexpr std::uint64_t kMinMemory = 1 * kMiB;
constexpr std::uint64_t kMaxMemory = 1 * kGiB;
constexpr Nanos kMinRotateDuration{1'000'000'000};
constexpr Nanos kMaxRotateDuration{86'400'000'000'000};

bool is_glob(const std::string& pattern) { return pattern.find_first_of("*?[") != std::string::npos; }

void parse_rotate(YamlReader& reader, const YAML::Node& node, const std::string& path, RecordingSpec& out) {
  if (!reader.check_map(node, path, {"size", "duration"})) return;
  if (has(node, "size")) {
    if (auto v = reader.size(node["size"], key(path, "size"), kMaxRotateSize)) {
      if (*v < kMiB) {
        reader.error_at(node["size"], key(path, "size"), "rotation size below 1MiB", "from 1MiB, e.g. 256MiB");
      } else {
        out.rotate_size = *v;
      }
    }
  }
  if (has(node, "duration")) {
    if (auto v = reader.duration(node["duration"], key(path, "duration"), false)) {
      if (*v < kMinRotateDuration || *v > kMaxRotateDuration) {
        reader.error_at(node["duration"], key(path, "duration"), "rotation duration out of range",
                        "from 1s to 24h, e.g. 10min");
      } else {
        out.rotate_duration = *v;
      }
    }
  }
}

void parse_sizes(YamlReader& reader, const YAML::Node& node, const std::string& path, RecordingSpec& out) {
  if (has(node, "chunk_size")) {
    if (auto v = reader.size(node["chunk_size"], key(path, "chunk_size"), kMaxChunk)) {
      if (*v < kMinChunk) {
        reader.error_at(node["chunk_size"], key(path, "chunk_size"), "chunk_size below 4KiB",
                        "from 4KiB to 64MiB, e.g. 1MiB");
      } else {
        out.chunk_size = *v;
      }
    }
  }
  if (has(node, "memory")) {
    if (auto v = reader.size(node["memory"], key(path, "memory"), kMaxMemory)) {
      if (*v < kMinMemory) {
        reader.error_at(node["memory"], key(path, "memory"), "memory below 1MiB", "from 1MiB to 1GiB, e.g. 16MiB");
      } else {
        out.memory = *v;
      }
    }
  }
  if (has(node, "rotate")) parse_rotate(reader, node["rotate"], key(path, "rotate"), out);
  if (out.rotate_size < out.chunk_size && has(node, "rotate")) {
    reader.error_at(node["rotate"], key(path, "rotate.size"), "rotation size below chunk_size",
                    "at least chunk_size (" + std::to_string(out.chunk_size) + " bytes)");
  }
}

}  // namespace

void parse_recording(YamlReader& reader, const YAML::Node& node, const std::string& path, RecordingSpec& out) {
  if (!reader.check_map(node, path,
                        {"directory", "channels", "compression", "typed_encoding", "chunk_size", "rotate", "memory",
                         "start", "candump"}))
    return;
  if (!has(node, "directory")) {
    reader.error_at(node, key(path, "directory"), "missing required key 'directory'",
                    "the directory the recordings go to, e.g. /var/lib/cosmicd/recordings");
    return;
  }
  if (auto v = reader.string(node["directory"], key(path, "directory"))) {
    const std::filesystem::path directory(*v);
    out.directory =
        directory.is_absolute()
            ? directory.lexically_normal().string()
            : (std::filesystem::absolute(reader.file()).parent_path() / directory).lexically_normal().string();
  }
  if (has(node, "channels") && reader.is_list(node["channels"], key(path, "channels"))) {
    // Strings, not names: a glob's * ? [ ] are no name's characters.
    for (std::size_t i = 0; i < node["channels"].size(); ++i) {
      if (auto v = reader.string(node["channels"][i], indexed(key(path, "channels"), i))) out.channels.push_back(*v);
    }
  }
  if (has(node, "compression")) {
    if (auto v = reader.choice(node["compression"], key(path, "compression"), {"zstd", "none"}))
      out.compression = *v == 0 ? RecordCompression::zstd : RecordCompression::none;
  }
  if (has(node, "typed_encoding")) {
    if (auto v = reader.choice(node["typed_encoding"], key(path, "typed_encoding"), {"cdr", "json"}))
      out.typed_encoding = *v == 0 ? TypedEncoding::cdr : TypedEncoding::json;
  }
  parse_sizes(reader, node, path, out);
  if (has(node, "start")) {
    if (auto v = reader.boolean(node["start"], key(path, "start"))) out.start = *v;
  }
  if (has(node, "candump")) {
    if (auto v = reader.string_list(node["candump"], key(path, "candump"))) out.candump = *v;
  }
}

void check_recording(YamlReader& reader, const YAML::Node& node, const std::string& path, const Config& config) {
  if (!config.recording.enabled()) return;
  const YAML::Node channels = has(node, "channels") ? node["channels"] : YAML::Node();
  for (std::size_t i = 0; channels.IsSequence() && i < channels.size(); ++i) {
    if (!channels[i].IsScalar()) continue;  // reported by parse_recording
    const std::string& name = channels[i].Scalar();
    if (is_glob(name) || config.find_channel(name) != nullptr) continue;
    reader.error_at(channels[i], indexed(key(path, "channels"), i), "unknown channel '" + name + "'",
                    "a channel of this file, or a glob such as 'drive*'");
  }
  const YAML::Node candump = has(node, "candump") ? node["candump"] : YAML::Node();
  for (std::size_t i = 0; candump.IsSequence() && i < candump.size(); ++i) {
    if (!candump[i].IsScalar()) continue;
    const std::string& name = candump[i].Scalar();
    const SegmentSpec* segment = config.find_segment(name);
    if (segment != nullptr && segment->type == SegmentType::can) continue;
    reader.error_at(
        candump[i], indexed(key(path, "candump"), i),
        segment == nullptr ? "unknown segment '" + name + "'" : "segment '" + name + "' is not a CAN segment",
        "a CAN segment of this file");
  }
}

}  // namespace cosmic::config_detail

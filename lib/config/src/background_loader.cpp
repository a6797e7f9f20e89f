#include "background_loader.hpp"
#include "type_file_loader.hpp"

#include <map>
#include <set>

#include "cosmic/can_background.hpp"
#include "cosmic/can_timing.hpp"
#include "cosmic/dbc.hpp"

namespace cosmic::config_detail {
namespace {

// Frames of one segment's background, YAML and DBC together: a bus carries far fewer.
constexpr std::size_t kMaxBackgroundFrames = 20'000;

std::string location(const std::string& file, const YAML::Mark& mark) {
  return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

class BackgroundParser {
 public:
  BackgroundParser(YamlReader& reader, CanSegmentProperties& can, std::vector<std::string>& included)
      : reader_(reader), can_(can), included_(included) {}

  void parse(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"frames", "dbc", "periods", "ignore"})) return;
    if (node["frames"] && reader_.is_list(node["frames"], key(path, "frames"))) {
      for (std::size_t i = 0; i < node["frames"].size(); ++i) {
        parse_frame(node["frames"][i], key(path, "frames") + "[" + std::to_string(i) + "]");
      }
    }
    if (node["dbc"]) {
      parse_dbc_options(node, path);
      if (const auto file = reader_.string(node["dbc"], key(path, "dbc"))) load_dbc(node["dbc"], path, *file);
    } else {
      for (const char* only_with_dbc : {"periods", "ignore"}) {
        if (node[only_with_dbc]) {
          reader_.error_at(node[only_with_dbc], key(path, only_with_dbc),
                           std::string(only_with_dbc) + " applies to a DBC's messages",
                           "a dbc: FILE beside it, or remove it");
        }
      }
    }
    if (!node["frames"] && !node["dbc"])
      reader_.error_at(node, path, "no background frames declared", "frames: [...] and/or dbc: FILE");
  }

 private:
  void parse_frame(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"name", "can_id", "extended", "dlc", "length", "period", "jitter"})) return;
    CanBackgroundFrame frame;
    bool ok = true;
    if (node["extended"]) ok = assign(reader_.boolean(node["extended"], key(path, "extended")), frame.extended) && ok;
    if (require(node, path, "can_id",
                "the frame's identifier, e.g. 0x123 (11 bits) or 0x18FF0001 with extended: true")) {
      const std::uint64_t max = frame.extended ? kExtendedIdMax : kStandardIdMax;
      std::uint64_t id = 0;
      ok = assign(reader_.unsigned_int(node["can_id"], key(path, "can_id"), 0, max), id) && ok;
      frame.can_id = static_cast<std::uint32_t>(id);
    } else {
      ok = false;
    }
    ok = parse_length(node, path, frame) && ok;
    if (require(node, path, "period", "the minimum time between two of its frames, e.g. 10ms")) {
      ok = assign(reader_.duration(node["period"], key(path, "period"), false), frame.period) && ok;
    } else {
      ok = false;
    }
    if (node["jitter"]) ok = assign(reader_.duration(node["jitter"], key(path, "jitter"), true), frame.jitter) && ok;
    if (!ok) return;
    frame.name = node["name"] ? reader_.string(node["name"], key(path, "name")).value_or("")
                              : can_id_text(frame.can_id, frame.extended);
    frame.origin = location(reader_.file(), node.Mark());
    if (const std::string conflict = add(std::move(frame)); !conflict.empty())
      reader_.error_at(node, path, conflict, "one sender per identifier");
  }

  // `dlc: 0..15` (the DLC code; 9..15 are FD lengths) or `length: NB` (data bytes).
  bool parse_length(const YAML::Node& node, const std::string& path, CanBackgroundFrame& frame) {
    const char* valid =
        can_.fd ? "dlc: 0..15 or length: 0..8, 12, 16, 20, 24, 32, 48 or 64B" : "dlc: 0..8 or length: 0B..8B";
    if (node["dlc"] && node["length"]) {
      reader_.error_at(node["length"], key(path, "length"), "dlc and length both given", valid);
      return false;
    }
    if (node["dlc"]) {
      std::uint64_t dlc = 0;
      if (!assign(reader_.unsigned_int(node["dlc"], key(path, "dlc"), 0, can_.fd ? 15 : 8), dlc)) return false;
      frame.length = dlc_length(static_cast<std::uint32_t>(dlc));
      return true;
    }
    if (!node["length"]) {
      reader_.error_at(node, path, "the frame's length is missing", valid);
      return false;
    }
    std::uint64_t length = 0;
    if (!assign(reader_.size(node["length"], key(path, "length"), kFdMaxPayload), length)) return false;
    frame.length = static_cast<std::uint32_t>(length);
    if (is_frame_length(frame.length, can_.fd)) return true;
    reader_.error_at(node["length"], key(path, "length"),
                     "no frame of this bus has " + std::to_string(length) + " data bytes", valid);
    return false;
  }

  void parse_dbc_options(const YAML::Node& node, const std::string& path) {
    if (const YAML::Node periods = node["periods"]) {
      if (!periods.IsMap()) {
        reader_.error_at(periods, key(path, "periods"), "expected a map of message names to periods",
                         "periods: {DoorEvent: 50ms}");
      } else {
        for (const auto& entry : periods) {
          const std::string name = entry.first.Scalar();
          if (const auto period = reader_.duration(entry.second, key(key(path, "periods"), name), false)) {
            periods_[name] = {*period, entry.first};
          }
        }
      }
    }
    if (node["ignore"]) {
      if (const auto names = reader_.string_list(node["ignore"], key(path, "ignore"))) {
        for (std::size_t i = 0; i < names->size(); ++i) ignored_[(*names)[i]] = node["ignore"][i];
      }
    }
  }

  // `path` is the background map's key path; `where` the dbc: value.
  void load_dbc(const YAML::Node& where, const std::string& path, const std::string& file) {
    const auto loaded = load_dbc_file(reader_, where, key(path, "dbc"), file, included_);
    if (!loaded) return;
    const std::string& resolved = loaded->path;
    const DbcFile& dbc = loaded->file;
    std::set<std::string> seen;
    for (const DbcMessage& m : dbc.messages) {
      seen.insert(m.name);
      if (ignored_.count(m.name)) continue;
      take_message(m, resolved, key(path, "dbc"));
    }
    for (const auto& [name, entry] : periods_) {
      if (!seen.count(name)) unknown_name(entry.second, key(key(path, "periods"), name), name, resolved);
    }
    for (const auto& [name, node] : ignored_) {
      if (!seen.count(name)) unknown_name(node, key(path, "ignore"), name, resolved);
    }
  }

  void take_message(const DbcMessage& m, const std::string& file, const std::string& path) {
    const std::string origin = file + ":" + std::to_string(m.line) + ":" + std::to_string(m.column);
    CanBackgroundFrame frame{m.name, m.can_id, m.extended, m.length, Nanos(0), Nanos(0), origin, std::nullopt};
    const auto declared = periods_.find(m.name);
    if (declared != periods_.end()) {
      frame.period = declared->second.first;
    } else if (m.cycle_time) {
      frame.period = *m.cycle_time;
    } else {
      reader_.error_in(ConfigError{file, m.line, m.column, path,
                                   "message " + m.name + " (" + can_id_text(m.can_id, m.extended) +
                                       ") has no GenMsgCycleTime: its minimum inter-arrival time is unknown",
                                   "periods: {" + m.name + ": 50ms} or ignore: [" + m.name + "] beside dbc:"});
      return;
    }
    if (!is_frame_length(m.length, can_.fd)) {
      reader_.error_in(ConfigError{
          file, m.line, m.column, path,
          "message " + m.name + " has " + std::to_string(m.length) + " data bytes, more than a frame of this bus",
          can_.fd ? "at most 64 bytes" : "at most 8 bytes (fd: true for CAN FD messages)"});
      return;
    }
    if (const std::string conflict = add(std::move(frame)); !conflict.empty()) {
      reader_.error_in(ConfigError{file, m.line, m.column, path, conflict, "one sender per identifier"});
    }
  }

  void unknown_name(const YAML::Node& node, const std::string& path, const std::string& name, const std::string& file) {
    reader_.error_at(node, path, "the DBC file " + file + " has no message named " + name,
                     "a BO_ message name of that file");
  }

  // Adds one more frame; the reason when it cannot be (two senders of one identifier would
  // collide on the bus), empty otherwise.
  std::string add(CanBackgroundFrame frame) {
    const auto id = std::pair(frame.can_id, frame.extended);
    if (const auto earlier = ids_.find(id); earlier != ids_.end()) {
      return "identifier " + can_id_text(frame.can_id, frame.extended) + " (" + frame.name +
             ") is already declared at " + earlier->second;
    }
    if (can_.background.size() >= kMaxBackgroundFrames) {
      return "more than " + std::to_string(kMaxBackgroundFrames) + " background frames on one segment";
    }
    ids_.emplace(id, frame.origin);
    can_.background.push_back(std::move(frame));
    return {};
  }

  bool require(const YAML::Node& node, const std::string& path, const char* name, const char* valid) {
    if (node[name]) return true;
    reader_.error_at(node, path, std::string("missing key '") + name + "'", valid);
    return false;
  }

  template <typename T, typename U>
  static bool assign(const std::optional<T>& value, U& out) {
    if (!value) return false;
    out = static_cast<U>(*value);
    return true;
  }

  YamlReader& reader_;
  CanSegmentProperties& can_;
  std::vector<std::string>& included_;
  std::map<std::string, std::pair<Nanos, YAML::Node>> periods_;
  std::map<std::string, YAML::Node> ignored_;
  std::map<std::pair<std::uint32_t, bool>, std::string> ids_;
};

}  // namespace

void parse_background(YamlReader& reader, const YAML::Node& node, const std::string& path, CanSegmentProperties& can,
                      std::vector<std::string>& included) {
  BackgroundParser(reader, can, included).parse(node, path);
}

}  // namespace cosmic::config_detail

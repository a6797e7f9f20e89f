#include "realtime_loader.hpp"

#include <thread>

namespace cosmic::config_detail {
namespace {

bool key_given(const YAML::Node& map, const char* name) { return map[name] && !map[name].IsNull(); }

void parse_priorities(YamlReader& reader, const YAML::Node& node, const std::string& path, RealtimeSpec& out) {
  if (!reader.check_map(node, path, {"hrt", "srt", "nrt", "receive"})) return;
  const std::pair<const char*, int*> fields[] = {{"hrt", &out.hrt_priority},
                                                 {"srt", &out.srt_priority},
                                                 {"nrt", &out.nrt_priority},
                                                 {"receive", &out.receive_priority}};
  for (const auto& [name, target] : fields) {
    if (!key_given(node, name)) continue;
    if (auto v = reader.unsigned_int(node[name], path + "." + name, 0, 99)) *target = static_cast<int>(*v);
  }
  // HRT must preempt SRT and NRT on the same CPU, so it may not be configured below them.
  const bool hrt_below =
      out.hrt_priority != 0 && (out.hrt_priority < out.srt_priority || out.hrt_priority < out.nrt_priority);
  const bool srt_below = out.srt_priority != 0 && out.srt_priority < out.nrt_priority;
  if (hrt_below || srt_below) {
    reader.error_at(node, path,
                    "class priorities are out of order (hrt " + std::to_string(out.hrt_priority) + ", srt " +
                        std::to_string(out.srt_priority) + ", nrt " + std::to_string(out.nrt_priority) + ")",
                    "hrt >= srt >= nrt, so a lower class never preempts a higher one");
  }
}

void parse_cpu_list(YamlReader& reader, const YAML::Node& node, const std::string& path, std::vector<int>& out) {
  if (!reader.is_list(node, path)) return;
  const unsigned available = std::max(1u, std::thread::hardware_concurrency());
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    if (auto v = reader.unsigned_int(node[i], item, 0, 1023)) {
      if (*v >= available) {
        reader.error_at(node[i], item, "CPU " + std::to_string(*v) + " does not exist on this machine",
                        "a CPU number below " + std::to_string(available));
        continue;
      }
      out.push_back(static_cast<int>(*v));
    }
  }
}

// `cpus: [..]` places every thread on those CPUs; `cpus: {hrt: [..], srt, nrt, receive, other}`
// places each kind on its own (a kind not named runs where `other` says, anywhere without it).
void parse_cpus(YamlReader& reader, const YAML::Node& node, const std::string& path, CpuPlacement& out) {
  if (node.IsSequence()) {
    std::vector<int> all;
    parse_cpu_list(reader, node, path, all);
    out = CpuPlacement{all, all, all, all, all};
    return;
  }
  if (!node.IsMap()) {
    reader.error_at(node, path, "expected a list of CPUs or a map of them by thread kind",
                    "cpus: [1] or cpus: {hrt: [1], srt: [1], nrt: [0], receive: [0], other: [0]}");
    return;
  }
  if (!reader.check_map(node, path, {"hrt", "srt", "nrt", "receive", "other"})) return;
  const std::pair<const char*, std::vector<int>*> kinds[] = {
      {"hrt", &out.hrt}, {"srt", &out.srt}, {"nrt", &out.nrt}, {"receive", &out.receive}, {"other", &out.other}};
  for (const auto& [name, target] : kinds) {
    if (key_given(node, name)) parse_cpu_list(reader, node[name], path + "." + name, *target);
  }
}

}  // namespace

void parse_realtime(YamlReader& reader, const YAML::Node& node, const std::string& path, RealtimeSpec& out) {
  if (!reader.check_map(node, path, {"priorities", "cpus", "lock_memory"})) return;
  if (key_given(node, "priorities")) parse_priorities(reader, node["priorities"], path + ".priorities", out);
  if (key_given(node, "cpus")) parse_cpus(reader, node["cpus"], path + ".cpus", out.cpus);
  if (key_given(node, "lock_memory")) {
    if (auto v = reader.boolean(node["lock_memory"], path + ".lock_memory")) out.lock_memory = *v;
  }
}

}  // namespace cosmic::config_detail

#include "components_loader.hpp"

#include "folded_names.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace cosmic::config_detail {
namespace {

bool present(const YAML::Node& map, const char* name) { return map.IsMap() && map[name] && !map[name].IsNull(); }

std::string item_path(const std::string& path, std::size_t index) { return path + "[" + std::to_string(index) + "]"; }

bool contains(const std::vector<std::string>& list, const std::string& value) {
  return std::find(list.begin(), list.end(), value) != list.end();
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "(none)" : out;
}

// Channel maps of the document by name, also the ones that failed to parse: a component naming
// a broken channel must not read "unknown channel" on top of the channel's own error.
struct ChannelNode {
  YAML::Node node;
  std::string path;  // channels[i]
};

std::map<std::string, ChannelNode> channel_nodes(const YAML::Node& root) {
  std::map<std::string, ChannelNode> out;
  const YAML::Node list = root["channels"];
  if (!list || !list.IsSequence()) return out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node node = list[i];
    if (node.IsMap() && node["name"] && node["name"].IsScalar())
      out.emplace(node["name"].Scalar(), ChannelNode{node, item_path("channels", i)});
  }
  return out;
}

class ComponentsLoader {
 public:
  ComponentsLoader(YamlReader& reader, const YAML::Node& root, Config& config)
      : reader_(reader), root_(root), config_(config), channels_(channel_nodes(root)) {}

  void run() {
    const YAML::Node list = root_["components"];
    if (present(root_, "components") && reader_.is_list(list, "components")) {
      for (std::size_t i = 0; i < list.size(); ++i) read_component(list[i], item_path("components", i));
    }
    for (auto& channel : config_.channels) complete_channel(channel);
  }

 private:
  struct Tags {  // where each component's P/S tags were written, for located errors
    YAML::Node node;
    std::string path;
  };

  void read_component(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"name", "segment", "publishes", "subscribes", "subject"})) return;
    const std::size_t errors_before = reader_.error_count();
    ComponentSpec c;
    if (require(node, path, "name", "a component name"))
      c.name = reader_.name(node["name"], path + ".name").value_or("");
    if (require(node, path, "segment", "the name of the segment the component lives on")) read_segment(node, path, c);
    if (present(node, "subject")) read_subject(node, path, c);
    read_list(node, path, "publishes", c.publishes);
    read_list(node, path, "subscribes", c.subscribes);
    if (!present(node, "publishes") && !present(node, "subscribes")) {
      reader_.error_at(node, path, "component neither publishes nor subscribes",
                       "publishes: [CHANNEL] and/or subscribes: [CHANNEL]");
    }
    if (reader_.error_count() != errors_before) return;
    if (const auto [it, fresh] = names_.emplace(c.name, node["name"].Mark().line + 1); !fresh) {
      reader_.error_at(node["name"], path + ".name", "duplicate component name '" + c.name + "'",
                       "a name not used by another component (first at line " + std::to_string(it->second) + ")");
      return;
    }
    if (!folded_.add(reader_, node["name"], path + ".name", "component", c.name)) return;
    tags_.emplace(c.name, Tags{node, path});
    config_.components.push_back(std::move(c));
  }

  bool require(const YAML::Node& node, const std::string& path, const char* name, const char* valid) {
    if (present(node, name)) return true;
    if (!node[name])
      reader_.error_at(node, path + "." + name, std::string("missing required key '") + name + "'", valid);
    return false;
  }

  void read_segment(const YAML::Node& node, const std::string& path, ComponentSpec& c) {
    const auto name = reader_.string(node["segment"], path + ".segment");
    if (!name) return;
    if (!config_.find_segment(*name)) {
      std::vector<std::string> known;
      for (const auto& s : config_.segments) known.push_back(s.name);
      reader_.error_at(node["segment"], path + ".segment", "unknown segment '" + *name + "'",
                       "one of the segments: " + joined(known));
      return;
    }
    if (config_.find_segment(*name)->type == SegmentType::replay) {
      reader_.error_at(node["segment"], path + ".segment",
                       "segment '" + *name + "' is a replay: it publishes a recording, no component lives there",
                       "a CAN, DDS or LCM segment");
      return;
    }
    c.segment = *name;
  }

  // The subject of the component's DDS Security certificate (RFC 2253, "CN=detector,O=cosmic"): only
  // a DDS segment authenticates participants by it.
  void read_subject(const YAML::Node& node, const std::string& path, ComponentSpec& c) {
    const std::string p = path + ".subject";
    const auto subject = reader_.string(node["subject"], p);
    if (!subject) return;
    if (subject->find('=') == std::string::npos) {
      reader_.error_at(node["subject"], p, "'" + *subject + "' is not a distinguished name",
                       "the subject of the component's certificate in RFC 2253 form, e.g. CN=detector,O=cosmic");
      return;
    }
    const SegmentSpec* segment = config_.find_segment(c.segment);
    if (segment != nullptr && segment->type != SegmentType::dds) {
      reader_.error_at(node["subject"], p,
                       "component on " + std::string(to_string(segment->type)) + " segment '" + c.segment +
                           "': only DDS Security authenticates a participant by its subject",
                       "remove subject, or place the component on a DDS segment");
      return;
    }
    c.subject = *subject;
  }

  void read_list(const YAML::Node& node, const std::string& path, const char* role, std::vector<std::string>& out) {
    if (!present(node, role)) return;
    const std::string p = path + "." + role;
    auto names = reader_.string_list(node[role], p);
    if (!names) return;
    std::set<std::string> seen;
    for (std::size_t i = 0; i < names->size(); ++i) {
      const std::string& name = (*names)[i];
      if (!channels_.count(name)) {
        reader_.error_at(node[role][i], item_path(p, i), "unknown channel '" + name + "'",
                         "one of the channels: " + channel_list());
      } else if (!seen.insert(name).second) {
        reader_.error_at(node[role][i], item_path(p, i), "channel '" + name + "' listed twice", "each channel once");
      }
    }
    out = *names;
  }

  std::string channel_list() const {
    std::vector<std::string> names;
    for (const auto& [name, node] : channels_) names.push_back(name);
    return joined(names);
  }

  // Segments, in the order of `segments:`, of the components that publish (or subscribe) `channel`;
  // an FMU (`fmus:`) is a component publishing its output channels and subscribing its input channels.
  std::vector<std::string> segments_of(const std::string& channel, bool publishes) const {
    std::vector<std::string> out;
    for (const auto& segment : config_.segments) {
      const bool component = std::any_of(config_.components.begin(), config_.components.end(), [&](const auto& c) {
        return c.segment == segment.name && contains(publishes ? c.publishes : c.subscribes, channel);
      });
      const bool fmu = std::any_of(config_.fmus.begin(), config_.fmus.end(), [&](const FmuSpec& f) {
        return f.segment == segment.name && contains(publishes ? f.publishes() : f.subscribes(), channel);
      });
      if (component || fmu) out.push_back(segment.name);
    }
    return out;
  }

  void complete_channel(ChannelSpec& channel) {
    const auto node = channels_.find(channel.name);
    if (node == channels_.end()) return;
    const YAML::Node& map = node->second.node;
    if (!present(map, "publishers")) channel.publishers = segments_of(channel.name, true);
    if (!present(map, "subscribers")) {
      channel.subscribers.clear();
      for (const auto& s : segments_of(channel.name, false)) {
        if (!contains(channel.publishers, s)) channel.subscribers.push_back(s);
      }
    }
    report_empty(map, node->second.path, "publishers", channel.publishers,
                 "a component that publishes it, or publishers: [SEGMENT]");
    report_empty(map, node->second.path, "subscribers", channel.subscribers,
                 "a component on another segment that subscribes it, or subscribers: [SEGMENT]");
    check_agreement(channel);
    check_fmu_agreement(channel);
  }

  // Whether an `fmus:` entry that was refused (with errors of its own) maps `channel` in `role`
  // ("outputs": it would have published it; "inputs": subscribed it).
  bool named_by_refused_fmu(const std::string& channel, const char* role) const {
    const YAML::Node list = root_["fmus"];
    if (!list || !list.IsSequence()) return false;
    for (const auto& entry : list) {
      if (!entry.IsMap() || !entry[role] || !entry[role].IsMap()) continue;
      const std::string name = entry["name"] && entry["name"].IsScalar() ? entry["name"].Scalar() : "";
      const bool loaded =
          std::any_of(config_.fmus.begin(), config_.fmus.end(), [&](const FmuSpec& f) { return f.name == name; });
      if (loaded) continue;
      for (auto it = entry[role].begin(); it != entry[role].end(); ++it)
        if (it->second.IsScalar() && it->second.Scalar().starts_with(channel + ".")) return true;
    }
    return false;
  }

  void report_empty(const YAML::Node& map, const std::string& path, const char* role,
                    const std::vector<std::string>& list, const char* valid) {
    if (!list.empty() || present(map, role)) return;
    // A refused FMU would have given the segment: its own errors say what to fix.
    if (named_by_refused_fmu(map["name"].Scalar(), std::string_view(role) == "publishers" ? "outputs" : "inputs"))
      return;
    reader_.error_at(map, path + "." + role, std::string("no ") + role + " given and none derived from components",
                     valid);
  }

  // A component's events only cross the gateway from a P segment of its channel, and it only
  // receives them on a P or S segment.
  void check_agreement(const ChannelSpec& channel) {
    for (const auto& c : config_.components) {
      const Tags& tags = tags_.at(c.name);
      if (contains(c.publishes, channel.name) && !contains(channel.publishers, c.segment)) {
        disagree(tags, "publishes", c, channel,
                 "a segment listed in its publishers (" + joined(channel.publishers) + ")");
      }
      if (contains(c.subscribes, channel.name) && !contains(channel.publishers, c.segment) &&
          !contains(channel.subscribers, c.segment)) {
        disagree(tags, "subscribes", c, channel,
                 "a segment among its publishers or subscribers (" + joined(channel.publishers) + "; " +
                     joined(channel.subscribers) + ")");
      }
    }
  }

  // As for components: an FMU's outputs leave from a P segment of their channel, its inputs arrive on
  // a P or S segment.
  void check_fmu_agreement(const ChannelSpec& channel) {
    for (const auto& f : config_.fmus) {
      if (contains(f.publishes(), channel.name) && !contains(channel.publishers, f.segment)) {
        fmu_disagrees(f, "outputs", channel, "a segment listed in its publishers (" + joined(channel.publishers) + ")");
      }
      if (contains(f.subscribes(), channel.name) && !contains(channel.publishers, f.segment) &&
          !contains(channel.subscribers, f.segment)) {
        fmu_disagrees(f, "inputs", channel,
                      "a segment among its publishers or subscribers (" + joined(channel.publishers) + "; " +
                          joined(channel.subscribers) + ")");
      }
    }
  }

  void fmu_disagrees(const FmuSpec& f, const char* role, const ChannelSpec& channel, const std::string& valid) {
    const YAML::Node list = root_["fmus"];
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!list[i].IsMap() || !list[i]["name"] || list[i]["name"].Scalar() != f.name) continue;
      const YAML::Node map = list[i][role];
      for (auto it = map.begin(); it != map.end(); ++it) {
        if (!it->second.IsScalar() || !it->second.Scalar().starts_with(channel.name + ".")) continue;
        reader_.error_at(it->second, item_path("fmus", i) + "." + role + "." + it->first.Scalar(),
                         "FMU '" + f.name + "' on segment '" + f.segment + "' " +
                             (std::string_view(role) == "outputs" ? "publishes" : "subscribes") + " '" + channel.name +
                             "', which the gateway does not bind there",
                         "an FMU on " + valid);
        return;
      }
    }
  }

  void disagree(const Tags& tags, const char* role, const ComponentSpec& c, const ChannelSpec& channel,
                const std::string& valid) {
    const YAML::Node list = tags.node[role];
    std::size_t index = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (list[i].IsScalar() && list[i].Scalar() == channel.name) index = i;
    }
    reader_.error_at(list[index], item_path(tags.path + "." + role, index),
                     "component '" + c.name + "' on segment '" + c.segment + "' " + role + " '" + channel.name +
                         "', which the gateway does not bind there",
                     "a component on " + valid);
  }

  YamlReader& reader_;
  const YAML::Node& root_;
  Config& config_;
  std::map<std::string, ChannelNode> channels_;
  std::map<std::string, int> names_;
  FoldedNames folded_;
  std::map<std::string, Tags> tags_;
};

}  // namespace

bool has_components(const YAML::Node& root) { return present(root, "components"); }

void load_components(YamlReader& reader, const YAML::Node& root, Config& config) {
  ComponentsLoader(reader, root, config).run();
}

}  // namespace cosmic::config_detail

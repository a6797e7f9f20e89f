#include "cosmic/config_loader.hpp"

#include <variant>

#include "cosmic/lcm_url.hpp"
#include "cosmic/transport_limits.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "cosmic/admission.hpp"
#include "background_loader.hpp"
#include "can_segment_loader.hpp"
#include "components_loader.hpp"
#include "fmus_loader.hpp"
#include "native_loader.hpp"
#include "secoc_loader.hpp"
#include "typed_hops_loader.hpp"
#include "type_loader.hpp"
#include "federation_loader.hpp"
#include "metrics_loader.hpp"
#include "realtime_loader.hpp"
#include "recording_loader.hpp"
#include "replay_loader.hpp"
#include "dds_security_loader.hpp"
#include "folded_names.hpp"
#include "key_file_loader.hpp"
#include "segment_overlap.hpp"
#include "yaml_reader.hpp"

namespace cosmic {
namespace {

using config_detail::has;
using config_detail::indexed;
using config_detail::key;
using config_detail::YamlReader;

constexpr std::uint64_t kMaxPayload = 1 << 20;

class ConfigParser {
 public:
  explicit ConfigParser(std::string file, LoadOptions options = {}) : reader_(std::move(file)), options_(options) {}

  ConfigResult parse_document(std::string_view text) {
    ConfigResult result;
    const auto root = load(text);
    if (!root) {
      result.errors = reader_.take_errors();
      return result;
    }
    if (reader_.check_map(*root, "", {"gateway", "segments", "channels", "components", "fmus", "recording"})) {
      if (has(*root, "gateway")) parse_gateway((*root)["gateway"]);
      if (require(*root, "", "segments", "a list of segments (type can, dds or lcm)"))
        parse_segments((*root)["segments"]);
      derive_bindings_ = config_detail::has_components(*root) || has(*root, "fmus");
      if (require(*root, "", "channels", "a list of channels")) parse_channel_list((*root)["channels"], "channels");
      if (has(*root, "gateway") && has((*root)["gateway"], "federation")) {
        config_detail::check_federation_segment(reader_, (*root)["gateway"]["federation"], "gateway.federation",
                                                config_);
      }
      config_detail::load_fmus(reader_, *root, config_, included_);
      config_detail::load_components(reader_, *root, config_);
      native_.check_derived(reader_, config_);
      secoc_.check_derived(reader_, config_);
      typed_.check(reader_, config_.channels, config_.segments);
      if (has(*root, "recording")) {
        config_detail::parse_recording(reader_, (*root)["recording"], "recording", config_.recording);
        config_detail::check_recording(reader_, (*root)["recording"], "recording", config_);
      }
    }
    result.config = std::move(config_);
    result.errors = reader_.take_errors();
    result.included_files = std::move(included_);
    return result;
  }

  ChannelsResult parse_bind_document(std::string_view text, const Config& running) {
    ChannelsResult result;
    config_.segments = running.segments;
    for (const auto& s : config_.segments) segment_names_.insert(s.name);
    const auto root = load(text);
    if (root) {
      if (root->IsMap() && (*root)["channels"]) {
        if (reader_.check_map(*root, "", {"channels"})) parse_channel_list((*root)["channels"], "channels");
      } else if (root->IsSequence()) {
        parse_channel_list(*root, "channels");
      } else if (root->IsMap()) {
        parse_channel_entry(*root, "channel");
      } else {
        reader_.error_at(*root, "", "expected channel definitions",
                         "a 'channels:' list, a list of channels or one channel map");
      }
      typed_.check(reader_, config_.channels, config_.segments);
      config_detail::add_fmu_publishers(running.fmus, config_.channels);
      if (config_.channels.empty() && reader_.error_count() == 0) {
        reader_.error_at(*root, "channels", "no channel to bind", "at least one channel definition");
      }
    }
    result.channels = std::move(config_.channels);
    result.errors = reader_.take_errors();
    return result;
  }

  SegmentResult parse_segment_document(std::string_view text, const Config& running) {
    SegmentResult result;
    if (const auto root = reader_.load(text, "a segment map")) {
      auto segment = parse_segment(*root, "segment");
      if (segment && running.find_segment(segment->name)) {
        reader_.error_at((*root)["name"], "segment.name", "a segment named '" + segment->name + "' is running",
                         "a name no segment of the gateway has");
      } else if (segment) {
        result.segment = std::move(*segment);
      }
    }
    result.errors = reader_.take_errors();
    return result;
  }

 private:
  std::optional<YAML::Node> load(std::string_view text) {
    return reader_.load(text, "a map with gateway, segments and channels");
  }

  bool require(const YAML::Node& map, const std::string& path, const char* name, const char* valid) {
    return reader_.require(map, path, name, valid);
  }

  void parse_gateway(const YAML::Node& node) {
    const std::string path = "gateway";
    if (!reader_.check_map(node, path,
                           {"name", "can_node_id", "residence_bound", "clean_interval", "realtime", "control_socket",
                            "metrics", "federation"})) {
      return;
    }
    GatewaySpec& g = config_.gateway;
    if (has(node, "name")) {
      if (auto v = reader_.name(node["name"], key(path, "name"))) g.name = *v;
    }
    if (has(node, "can_node_id")) {
      if (auto v = reader_.unsigned_int(node["can_node_id"], key(path, "can_node_id"), 0, 127)) {
        g.can_node_id = static_cast<std::uint8_t>(*v);
      }
    }
    if (has(node, "residence_bound")) {
      if (auto v = reader_.duration(node["residence_bound"], key(path, "residence_bound"), false))
        g.residence_bound = *v;
    }
    if (has(node, "clean_interval")) {
      if (auto v = reader_.duration(node["clean_interval"], key(path, "clean_interval"), false)) g.clean_interval = *v;
    }
    if (has(node, "realtime")) parse_realtime(reader_, node["realtime"], key(path, "realtime"), g.realtime);
    if (has(node, "control_socket")) {
      if (auto v = reader_.string(node["control_socket"], key(path, "control_socket"))) {
        if (v->front() != '/') {
          reader_.error_at(node["control_socket"], key(path, "control_socket"), "'" + *v + "' is not an absolute path",
                           "an absolute path such as /run/cosmicd/control.sock");
        } else if (v->size() > 100) {
          reader_.error_at(node["control_socket"], key(path, "control_socket"), "path is too long for a Unix socket",
                           "at most 100 characters");
        } else {
          g.control_socket = *v;
        }
      }
    }
    if (has(node, "metrics")) {
      if (auto m = config_detail::parse_metrics(reader_, node["metrics"], key(path, "metrics"))) g.metrics = *m;
    }
    if (has(node, "federation"))
      config_detail::parse_federation(reader_, node["federation"], key(path, "federation"), g.federation);
  }

  void parse_segments(const YAML::Node& node) {
    if (!reader_.is_list(node, "segments")) return;
    std::map<std::string, YAML::Mark> first_seen;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string path = indexed("segments", i);
      auto segment = parse_segment(node[i], path);
      if (!segment) {
        // Known by name even when invalid: channels naming it must not read "unknown segment".
        const YAML::Node name = node[i].IsMap() ? node[i]["name"] : YAML::Node();
        if (name && name.IsScalar()) segment_names_.insert(name.Scalar());
        continue;
      }
      if (!first_seen.emplace(segment->name, node[i].Mark()).second) {
        reader_.error_at(node[i]["name"], key(path, "name"), "duplicate segment name '" + segment->name + "'",
                         "a name not used by another segment (first at line " +
                             std::to_string(first_seen[segment->name].line + 1) + ")");
        continue;
      }
      if (!folded_segments_.add(reader_, node[i]["name"], key(path, "name"), "segment", segment->name)) continue;
      config_detail::check_segment_overlap(node, i, *segment, config_.segments, reader_);
      segment_names_.insert(segment->name);
      config_.segments.push_back(std::move(*segment));
    }
  }

  std::optional<SegmentSpec> parse_segment(const YAML::Node& node, const std::string& path) {
    if (!node.IsMap()) {
      reader_.error_at(node, path, "expected a segment map", "keys name, type and the keys of that type");
      return std::nullopt;
    }
    const std::size_t errors_before = reader_.error_count();
    SegmentSpec s;
    std::optional<std::size_t> type;
    if (require(node, path, "type", "type: can, dds, lcm or replay"))
      type = reader_.choice(node["type"], key(path, "type"), {"can", "dds", "lcm", "replay"});
    if (require(node, path, "name", "a segment name")) {
      if (auto v = reader_.name(node["name"], key(path, "name"))) s.name = *v;
    }
    if (!type) {
      reader_.check_map(node, path,
                        {"name",
                         "type",
                         "interface",
                         "profile",
                         "bitrate",
                         "fd",
                         "data_bitrate",
                         "errors",
                         "max_utilization",
                         "background",
                         "domain",
                         "latency_bound",
                         "bandwidth",
                         "reliability",
                         "realtime",
                         "max_message_size",
                         "interfaces",
                         "discovery_server",
                         "shared_memory",
                         "url",
                         "network",
                         "own_datagrams",
                         "auth",
                         "security",
                         "file",
                         "channels",
                         "speed",
                         "loop",
                         "start_offset"});
      return std::nullopt;
    }
    s.type = static_cast<SegmentType>(*type);
    if (has(node, "max_utilization")) {
      if (auto v = reader_.percent(node["max_utilization"], key(path, "max_utilization"))) s.max_utilization = *v;
    }
    if (has(node, "network")) {
      if (auto v = reader_.name(node["network"], key(path, "network"))) s.network = *v;
    }
    switch (s.type) {
      case SegmentType::can:
        config_detail::parse_can(reader_, node, path, s, included_);
        break;
      case SegmentType::dds:
        parse_dds(node, path, s);
        break;
      case SegmentType::lcm:
        parse_lcm(node, path, s);
        break;
      case SegmentType::replay:
        config_detail::parse_replay(reader_, node, path, s, included_);
        break;
    }
    if (reader_.error_count() != errors_before) return std::nullopt;
    return s;
  }

  void parse_ip_common(const YAML::Node& node, const std::string& path, SegmentSpec& s) {
    if (has(node, "latency_bound")) {
      if (auto v = reader_.duration(node["latency_bound"], key(path, "latency_bound"), false)) s.latency_bound = *v;
    }
    if (has(node, "bandwidth")) {
      if (auto v = reader_.bitrate(node["bandwidth"], key(path, "bandwidth"))) s.bandwidth = *v;
    }
    if (has(node, "realtime")) {
      if (auto v = reader_.boolean(node["realtime"], key(path, "realtime"))) s.realtime = *v;
    }
    if (has(node, "max_message_size")) {
      if (auto v = reader_.size(node["max_message_size"], key(path, "max_message_size"), 64ull << 20)) {
        if (*v <= kIpMinMessage) {
          reader_.error_at(node["max_message_size"], key(path, "max_message_size"), "too small",
                           "more than " + std::to_string(kIpMinMessage) + "B");
        }
        s.max_message_size = *v;
      }
    }
  }

  void parse_dds(const YAML::Node& node, const std::string& path, SegmentSpec& s) {
    reader_.check_map(
        node, path,
        {"name", "type", "domain", "latency_bound", "bandwidth", "reliability", "realtime", "max_message_size",
         "interfaces", "discovery_server", "shared_memory", "max_utilization", "network", "security"});
    parse_ip_common(node, path, s);
    if (has(node, "domain")) {
      if (auto v = reader_.unsigned_int(node["domain"], key(path, "domain"), 0, 232))
        s.dds.domain = static_cast<std::uint32_t>(*v);
    }
    if (has(node, "reliability")) {
      if (auto v = reader_.choice(node["reliability"], key(path, "reliability"), {"reliable", "best_effort"})) {
        s.reliability = static_cast<Reliability>(*v);
      }
    }
    if (has(node, "interfaces")) {
      if (auto v = reader_.string_list(node["interfaces"], key(path, "interfaces"))) s.dds.interfaces = *v;
    }
    if (has(node, "discovery_server")) {
      if (auto v = reader_.string(node["discovery_server"], key(path, "discovery_server"))) {
        const auto colon = v->rfind(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == v->size()) {
          reader_.error_at(node["discovery_server"], key(path, "discovery_server"), "'" + *v + "' is not IP:PORT",
                           "an IPv4 address and port, e.g. 127.0.0.1:11811");
        }
        s.dds.discovery_server = *v;
      }
    }
    if (has(node, "shared_memory")) parse_shared_memory(node["shared_memory"], key(path, "shared_memory"), s);
    if (has(node, "security"))
      s.dds.security = config_detail::parse_dds_security(reader_, node["security"], key(path, "security"), included_,
                                                         options_.security_documents_pending);
  }

  // `shared_memory: [srt, nrt]`: the classes whose participant also uses Fast DDS's shared memory.
  void parse_shared_memory(const YAML::Node& node, const std::string& path, SegmentSpec& s) {
    if (!reader_.is_list(node, path)) return;
    s.dds.shared_memory = {false, false, false};
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (auto v = reader_.choice(node[i], indexed(path, i), {"hrt", "srt", "nrt"})) s.dds.shared_memory[*v] = true;
    }
  }

  void parse_lcm(const YAML::Node& node, const std::string& path, SegmentSpec& s) {
    reader_.check_map(node, path,
                      {"name", "type", "url", "latency_bound", "bandwidth", "realtime", "max_message_size",
                       "max_utilization", "network", "own_datagrams", "auth"});
    s.reliability = Reliability::best_effort;
    parse_ip_common(node, path, s);
    if (has(node, "url")) {
      if (auto v = reader_.string(node["url"], key(path, "url"))) {
        const auto lcm_url = parse_lcm_url(*v);
        if (!lcm_url) {
          reader_.error_at(node["url"], key(path, "url"), "unsupported LCM URL " + lcm_url.error().text,
                           "udpm://GROUP:PORT?ttl=N or memq://");
        }
        s.lcm.url = *v;
      }
    }
    if (has(node, "own_datagrams")) {
      s.lcm.own_datagrams = static_cast<LcmOwnDatagrams>(
          reader_.choice(node["own_datagrams"], key(path, "own_datagrams"), {"cut", "drop"}).value_or(0));
    }
    if (has(node, "auth"))
      s.lcm.auth = config_detail::parse_lcm_auth(reader_, node["auth"], key(path, "auth"), included_);
  }

  void parse_channel_list(const YAML::Node& node, const std::string& path) {
    if (!reader_.is_list(node, path)) return;
    for (std::size_t i = 0; i < node.size(); ++i) parse_channel_entry(node[i], indexed(path, i));
  }

  void parse_channel_entry(const YAML::Node& node, const std::string& path) {
    auto channel = parse_channel(node, path);
    if (!channel) return;
    if (!check_unique(node, path, *channel)) return;
    const bool derived = derive_bindings_ && !(node["publishers"] && node["subscribers"]);
    if (node["native"]) native_.add(reader_, node["native"], key(path, "native"), *channel, derived);
    if (node["secoc"]) secoc_.add(reader_, node["secoc"], key(path, "secoc"), *channel, derived);
    typed_.add(node, path, *channel);
    config_.channels.push_back(std::move(*channel));
  }

  bool check_unique(const YAML::Node& node, const std::string& path, const ChannelSpec& c) {
    bool ok = true;
    if (const auto [it, fresh] = channel_names_.emplace(c.name, node["name"].Mark().line + 1); !fresh) {
      reader_.error_at(node["name"], key(path, "name"), "duplicate channel name '" + c.name + "'",
                       "a name not used by another channel (first at line " + std::to_string(it->second) + ")");
      ok = false;
    }
    if (const auto [it, fresh] = subjects_.emplace(c.subject, c.name); !fresh) {
      reader_.error_at(node["subject"], key(path, "subject"), "subject already used by channel '" + it->second + "'",
                       "one channel per subject");
      ok = false;
    }
    if (c.etag) {
      if (const auto [it, fresh] = etags_.emplace(*c.etag, c.name); !fresh) {
        reader_.error_at(node["etag"], key(path, "etag"), "etag already used by channel '" + it->second + "'",
                         "a distinct etag per channel, or none (assigned)");
        ok = false;
      }
    }
    return ok;
  }

  std::optional<ChannelSpec> parse_channel(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(
            node, path,
            {"name", "subject", "class", "period", "max_rate", "reaction_time", "omission_degree", "temp_validity",
             "payload", "etag", "encoding", "publishers", "subscribers", "native", "type", "on_range", "secoc"})) {
      return std::nullopt;
    }
    const std::size_t errors_before = reader_.error_count();
    ChannelSpec c;
    if (require(node, path, "name", "a channel name"))
      c.name = reader_.name(node["name"], key(path, "name")).value_or("");
    if (require(node, path, "subject", "a 64-bit subject UID, e.g. 0x0000000100000042")) {
      c.subject = reader_.unsigned_int(node["subject"], key(path, "subject"), 1, UINT64_MAX).value_or(0);
    }
    if (require(node, path, "class", "class: hrt, srt or nrt")) {
      c.cls = static_cast<ChannelClass>(
          reader_.choice(node["class"], key(path, "class"), {"hrt", "srt", "nrt"}).value_or(2));
    }
    parse_timing(node, path, c);
    if (has(node, "omission_degree")) {
      c.omission_degree = static_cast<std::uint32_t>(
          reader_.unsigned_int(node["omission_degree"], key(path, "omission_degree"), 0, 1'000'000).value_or(0));
    }
    if (has(node, "payload")) c.payload = reader_.size(node["payload"], key(path, "payload"), kMaxPayload).value_or(0);
    if (has(node, "etag")) {
      if (auto v = reader_.unsigned_int(node["etag"], key(path, "etag"), 101, 16383))
        c.etag = static_cast<std::uint16_t>(*v);
    }
    if (has(node, "encoding")) {
      c.lcm_encoding = static_cast<LcmEncoding>(
          reader_.choice(node["encoding"], key(path, "encoding"), {"envelope", "raw"}).value_or(0));
    }
    if (node["type"]) c.type = config_detail::parse_channel_type(reader_, node["type"], key(path, "type"), included_);
    config_detail::parse_on_range(reader_, node, path, c);
    parse_bindings(node, path, c);
    if (node["native"]) {
      config_detail::parse_native(reader_, node["native"], key(path, "native"), config_, c, included_);
      // With components, the lists are derived later (check_derived_native_segments).
      if (!derive_bindings_ || (node["publishers"] && node["subscribers"])) {
        config_detail::check_native_segments(reader_, node["native"], key(path, "native"), c);
      }
    }
    if (node["secoc"]) config_detail::parse_secoc(reader_, node["secoc"], key(path, "secoc"), config_, c, included_);
    check_transport_limits(node, path, c);
    if (reader_.error_count() != errors_before) return std::nullopt;
    return c;
  }

  void parse_timing(const YAML::Node& node, const std::string& path, ChannelSpec& c) {
    const bool realtime = c.cls != ChannelClass::nrt;
    if (has(node, "period") && has(node, "max_rate")) {
      reader_.error_at(node["max_rate"], key(path, "max_rate"), "period and max_rate both given", "one of them");
    } else if (has(node, "period")) {
      c.period = reader_.duration(node["period"], key(path, "period"), false);
    } else if (has(node, "max_rate")) {
      if (auto hz = reader_.frequency(node["max_rate"], key(path, "max_rate"))) {
        // Minimum inter-arrival time, rounded down: a conservative (higher) load.
        c.period = period_of_rate(*hz);
      }
    } else if (realtime && !node["period"] && !node["max_rate"]) {  // a key without value: check_map said so
      reader_.error_at(node, key(path, "period"), "an hrt or srt channel needs period or max_rate",
                       "period: 10ms or max_rate: 100Hz");
    }
    if (has(node, "reaction_time")) {
      c.reaction_time = reader_.duration(node["reaction_time"], key(path, "reaction_time"), false);
    } else if (realtime && !node["reaction_time"]) {
      reader_.error_at(node, key(path, "reaction_time"), "an hrt or srt channel needs reaction_time",
                       "the end-to-end latency bound, e.g. reaction_time: 5ms");
    }
    if (has(node, "temp_validity"))
      c.temp_validity = reader_.duration(node["temp_validity"], key(path, "temp_validity"), false);
  }

  void parse_bindings(const YAML::Node& node, const std::string& path, ChannelSpec& c) {
    std::set<std::string> publishers;
    for (const char* role : {"publishers", "subscribers"}) {
      const std::string p = key(path, role);
      if (derive_bindings_ && !node[role]) continue;  // taken from the components (components_loader)
      if (!require(node, path, role, "a non-empty list of segment names")) continue;
      auto names = reader_.string_list(node[role], p);
      if (!names) continue;
      if (names->empty()) {
        reader_.error_at(node[role], p, "no segment listed", "at least one segment name");
        continue;
      }
      std::set<std::string> seen;
      for (std::size_t i = 0; i < names->size(); ++i) {
        const std::string& name = (*names)[i];
        const YAML::Node item = node[role][i];
        const std::string ip = indexed(p, i);
        if (!segment_names_.count(name)) {
          reader_.error_at(item, ip, "unknown segment '" + name + "'", "one of the segments: " + segment_list());
        } else if (!seen.insert(name).second) {
          reader_.error_at(item, ip, "segment '" + name + "' listed twice", "each segment once");
        } else if (std::string(role) == "subscribers" && publishers.count(name)) {
          reader_.error_at(item, ip, "segment '" + name + "' is both publisher and subscriber of this channel",
                           "a segment is either P or S of a channel");
        }
      }
      if (std::string(role) == "publishers") {
        publishers = seen;
        c.publishers = *names;
      } else {
        c.subscribers = *names;
      }
    }
  }

  // The same limits the adapters apply (cosmic/transport_limits.hpp): refused here, with a
  // location, rather than bound and silent at run time.
  void check_transport_limits(const YAML::Node& node, const std::string& path, const ChannelSpec& c) {
    std::set<std::string> reported;
    for (const auto* names : {&c.publishers, &c.subscribers}) {
      for (const auto& name : *names) {
        const SegmentSpec* segment = config_.find_segment(name);
        if (!segment) continue;
        const Result<void> carried = check_transport_name(segment->type, c.name);
        if (!carried && reported.insert(carried.error().text).second) {
          reader_.error_at(node["name"], key(path, "name"),
                           "segment '" + name + "' cannot carry this channel: " + carried.error().text,
                           "a shorter name");
        }
      }
    }
  }

  std::string segment_list() const {
    std::string out;
    for (const auto& name : segment_names_) out += (out.empty() ? "" : ", ") + name;
    return out.empty() ? "(none defined)" : out;
  }

  static constexpr std::uint64_t kIpMinMessage = kIpOverheadBytes;

  YamlReader reader_;
  LoadOptions options_;
  Config config_;
  bool derive_bindings_ = false;  // the document has components: P/S lists may be left out
  std::set<std::string> segment_names_;
  std::map<std::string, int> channel_names_;
  config_detail::FoldedNames folded_segments_;
  std::map<std::uint64_t, std::string> subjects_;
  std::map<std::uint16_t, std::string> etags_;
  std::vector<std::string> included_;  // files read besides the YAML (DBC)
  config_detail::NativeDeclarations native_;
  config_detail::SecocDeclarations secoc_;
  config_detail::TypedHopChecks typed_;
};

}  // namespace

ConfigResult parse_config(std::string_view text, const std::string& file_name, const LoadOptions& options) {
  return ConfigParser(file_name, options).parse_document(text);
}

SegmentResult parse_segment(std::string_view text, const std::string& file_name, const Config& running) {
  return ConfigParser(file_name).parse_segment_document(text, running);
}

ChannelsResult parse_channels(std::string_view text, const std::string& file_name, const Config& running) {
  return ConfigParser(file_name).parse_bind_document(text, running);
}

}  // namespace cosmic

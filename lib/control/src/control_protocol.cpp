#include "cosmic/control_protocol.hpp"

#include <algorithm>

#include "cosmic/report.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::json;

Json failure(const std::string& code, const std::string& message) {
  return Json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}};
}

const ChannelStatsSnapshot* find_stats(const std::vector<ChannelStatsSnapshot>& stats, const std::string& name) {
  const auto it = std::find_if(stats.begin(), stats.end(), [&](const auto& s) { return s.name == name; });
  return it == stats.end() ? nullptr : &*it;
}

Json bind_answer(const BindResult& result) {
  Json out{{"ok", result.applied}, {"applied", result.applied}, {"channels", Json::array()}};
  for (const auto& c : result.channels) out["channels"].push_back(to_json(c));
  const bool rejected = std::any_of(result.channels.begin(), result.channels.end(),
                                    [](const ChannelReport& c) { return c.verdict == Verdict::rejected; });
  if (!result.applied) out["error"] = {{"code", rejected ? "rejected" : "bind_failed"}, {"message", result.error}};
  return out;
}

}  // namespace

ControlProtocol::ControlProtocol(Gateway& gateway, std::function<ConfigResult()> reload_source, AccessPolicy policy,
                                 Logger& log, ChangeObserver on_change)
    : gateway_(gateway),
      reload_source_(std::move(reload_source)),
      policy_(std::move(policy)),
      log_(log),
      on_change_(std::move(on_change)),
      started_(std::chrono::steady_clock::now()) {}

bool ControlProtocol::is_mutating(std::string_view command) {
  return command == "bind" || command == "unbind" || command == "reload";
}

std::string ControlProtocol::handle(std::string_view request_line, const PeerCredentials& peer) {
  Json response;
  const Json request = Json::parse(request_line, nullptr, false);
  if (request.is_discarded() || !request.is_object()) {
    response = failure("bad_request", "the request is not a JSON object");
  } else if (!request.contains("command") || !request["command"].is_string()) {
    response = failure("bad_request", "the request has no \"command\" string");
  } else {
    try {
      response = dispatch(request, peer);
    } catch (const Json::exception& e) {
      response = failure("bad_request", std::string("malformed request: ") + e.what());
    } catch (const std::exception& e) {
      response = failure("internal_error", e.what());
    }
  }
  // Texts quoted from files or interfaces may hold invalid UTF-8: replace it, never throw.
  return response.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

Json ControlProtocol::dispatch(const Json& request, const PeerCredentials& peer) {
  const std::string command = request["command"].get<std::string>();
  const bool mutating = is_mutating(command);
  if (!(mutating ? policy_.may_modify(peer) : policy_.may_read(peer))) {
    log_.log(LogLevel::warning, "denied " + command + " to uid " + std::to_string(peer.uid) + " pid " + std::to_string(peer.pid));
    return failure("permission_denied", std::string("uid ") + std::to_string(peer.uid) + " may not " +
                                            (mutating ? "change the gateway (" + command + ")" : "read gateway state"));
  }
  if (mutating) {
    log_.log(LogLevel::notice, "audit: uid " + std::to_string(peer.uid) + " pid " + std::to_string(peer.pid) + " runs " +
                                   command + (request.contains("name") ? " " + request["name"].dump() : ""));
  }
  if (command == "status") return status();
  if (command == "segments") return segments();
  if (command == "channels") return channels();
  if (command == "channel") return channel(request);
  if (mutating) {
    Json answer = command == "bind" ? bind(request) : command == "unbind" ? unbind(request) : reload();
    if (answer.value("ok", false) && on_change_) on_change_(command, request);
    return answer;
  }
  return failure("unknown_command", "unknown command '" + command +
                                        "' (status, segments, channels, channel, bind, unbind, reload)");
}

Json ControlProtocol::status() const {
  const AdmissionReport report = gateway_.admission();
  std::size_t bound = 0;
  std::size_t degraded = 0;
  for (const auto& c : report.channels) {
    if (c.verdict == Verdict::bound) ++bound;
    if (c.verdict == Verdict::degraded) ++degraded;
  }
  std::size_t up = 0;
  const auto segments = gateway_.segments();
  for (const auto& s : segments) up += s.health.state == SegmentHealth::up ? 1 : 0;
  const double uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  char id[20];
  std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(gateway_.identity().id));
  return Json{{"ok", true},
              {"gateway", {{"name", gateway_.identity().name}, {"id", id}, {"uptime_s", uptime}}},
              {"segments", {{"total", segments.size()}, {"up", up}}},
              {"channels", {{"bound", bound}, {"degraded", degraded}}},
              {"router", {{"queued", gateway_.router().queued()}, {"progress", gateway_.router().progress()}}}};
}

Json ControlProtocol::segments() const {
  Json list = Json::array();
  for (const auto& s : gateway_.segments()) {
    Json entry{{"name", s.spec.name},
               {"type", to_string(s.spec.type)},
               {"health", to_string(s.health.state)},
               {"detail", s.health.detail},
               {"utilization", s.utilization},
               {"max_utilization", s.spec.max_utilization},
               {"channels", s.channels},
               {"unrouted", s.unrouted},
               {"adapter",
                {{"received", s.adapter.received},
                 {"sent", s.adapter.sent},
                 {"receive_errors", s.adapter.receive_errors},
                 {"send_errors", s.adapter.send_errors},
                 {"overflow_drops", s.adapter.overflow_drops},
                 {"backlog", s.adapter.backlog}}}};
    if (s.spec.type == SegmentType::can) {
      entry["interface"] = s.spec.can.interface;
      entry["bitrate"] = s.spec.can.bitrate.bits_per_second;
    } else if (s.spec.type == SegmentType::dds) {
      entry["domain"] = s.spec.dds.domain;
    } else {
      entry["url"] = s.spec.lcm.url;
    }
    list.push_back(std::move(entry));
  }
  return Json{{"ok", true}, {"segments", list}};
}

Json ControlProtocol::channel_entry(const ChannelReport& verdict, const ChannelStatsSnapshot* stats) const {
  const ChannelSpec* spec = gateway_.knowledge_base().find_bound(verdict.name);
  Json entry{{"name", verdict.name}, {"class", to_string(verdict.cls)}, {"verdict", to_string(verdict.verdict)},
             {"reasons", verdict.reasons}, {"segments", Json::array()}};
  if (spec) {
    char subject[24];
    std::snprintf(subject, sizeof subject, "0x%016llx", static_cast<unsigned long long>(spec->subject));
    entry["subject"] = subject;
  }
  if (const auto etag = gateway_.knowledge_base().etag_of(verdict.name)) entry["etag"] = *etag;
  for (const auto& hop : verdict.hops) {
    Json seg{{"segment", hop.segment}, {"role", to_string(hop.role)}, {"rx", 0}, {"tx", 0}, {"dropped", Json::object()}};
    const auto matched = gateway_.matched_peers(hop.segment, verdict.name);
    seg["matched"] = matched ? Json(*matched) : Json(nullptr);
    for (std::size_t r = 0; r < kDropReasonCount; ++r) seg["dropped"][to_string(static_cast<DropReason>(r))] = 0;
    if (stats) {
      for (const auto& counters : stats->segments) {
        if (counters.segment != hop.segment) continue;
        seg["rx"] = counters.rx;
        seg["tx"] = counters.tx;
        for (std::size_t r = 0; r < kDropReasonCount; ++r) {
          seg["dropped"][to_string(static_cast<DropReason>(r))] = counters.dropped[r];
        }
      }
    }
    entry["segments"].push_back(std::move(seg));
  }
  entry["forwarded"] = stats ? stats->forwarded : 0;
  entry["residence"] = {{"p50_s", stats ? to_seconds(stats->residence_p50) : 0.0},
                        {"p99_s", stats ? to_seconds(stats->residence_p99) : 0.0},
                        {"max_s", stats ? to_seconds(stats->residence_max) : 0.0}};
  return entry;
}

Json ControlProtocol::channels() const {
  const auto stats = gateway_.channel_stats();
  Json list = Json::array();
  for (const auto& verdict : gateway_.admission().channels) list.push_back(channel_entry(verdict, find_stats(stats, verdict.name)));
  return Json{{"ok", true}, {"channels", list}};
}

Json ControlProtocol::channel(const Json& request) const {
  if (!request.contains("name") || !request["name"].is_string()) return failure("bad_request", "\"name\" (string) is required");
  const std::string name = request["name"].get<std::string>();
  const AdmissionReport report = gateway_.admission();
  const ChannelReport* verdict = report.find(name);
  if (!verdict) return failure("not_found", "no bound channel named '" + name + "'");
  const auto stats = gateway_.channel_stats();
  Json entry = channel_entry(*verdict, find_stats(stats, name));
  entry["admission"] = to_json(*verdict);
  return Json{{"ok", true}, {"channel", entry}};
}

Json ControlProtocol::bind(const Json& request) {
  if (!request.contains("yaml") || !request["yaml"].is_string()) {
    return failure("bad_request", "\"yaml\" (string with channel definitions) is required");
  }
  const std::string file = request.contains("file") && request["file"].is_string() ? request["file"].get<std::string>() : "request";
  const ChannelsResult parsed = parse_channels(request["yaml"].get<std::string>(), file, gateway_.config());
  if (!parsed.ok()) {
    Json out = failure("config_error", std::to_string(parsed.errors.size()) + " error(s) in the channel definitions");
    out["errors"] = to_json(parsed.errors);
    return out;
  }
  return bind_answer(gateway_.bind(parsed.channels));
}

Json ControlProtocol::unbind(const Json& request) {
  if (!request.contains("name") || !request["name"].is_string()) return failure("bad_request", "\"name\" (string) is required");
  const std::string name = request["name"].get<std::string>();
  if (!gateway_.unbind(name)) return failure("not_found", "no bound channel named '" + name + "'");
  return Json{{"ok", true}, {"unbound", name}};
}

Json ControlProtocol::reload() {
  const ConfigResult loaded = reload_source_();
  if (!loaded.ok()) {
    Json out = failure("config_error", std::to_string(loaded.errors.size()) +
                                           " error(s) in the configuration; the running configuration is unchanged");
    out["errors"] = to_json(loaded.errors);
    return out;
  }
  const BindResult result = gateway_.reload(loaded.config);
  Json out = bind_answer(result);
  if (!result.applied) out["error"] = {{"code", "reload_failed"}, {"message", result.error}};
  return out;
}

}  // namespace cosmic

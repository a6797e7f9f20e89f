#include "cosmic/control_protocol.hpp"

#include <algorithm>

#include "cosmic/can_background.hpp"
#include "cosmic/federation.hpp"
#include "cosmic/json_nesting.hpp"
#include "cosmic/report.hpp"

#include "bind_answer.hpp"
#include "echo_taps.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::json;

// A client-chosen text fit for one log line: printable ASCII, at most kMaxLoggedText characters.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, kMaxLoggedText)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > kMaxLoggedText) out += "...(" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string names_of(const std::vector<ChannelSpec>& channels) {
  std::string out;
  for (std::size_t i = 0; i < channels.size() && i < 3; ++i) out += (i ? ", " : "") + channels[i].name;
  if (channels.size() > 3) out += " and " + std::to_string(channels.size() - 3) + " more";
  return out;
}

const ChannelStatsSnapshot* find_stats(const std::vector<ChannelStatsSnapshot>& stats, const std::string& name) {
  const auto it = std::find_if(stats.begin(), stats.end(), [&](const auto& s) { return s.name == name; });
  return it == stats.end() ? nullptr : &*it;
}

void replace_or_bind(BindPlan& plan) {
  if (plan.replacing) {
    Gateway::plan_replace(plan);
  } else {
    Gateway::plan_bind(plan);
  }
}

}  // namespace

ControlProtocol::ControlProtocol(Gateway& gateway, std::function<ConfigResult()> reload_source, AccessPolicy policy,
                                 Logger& log, ChangeObserver on_change, Offload offload)
    : gateway_(gateway),
      reload_source_(std::move(reload_source)),
      policy_(std::move(policy)),
      log_(log),
      on_change_(std::move(on_change)),
      offload_(std::move(offload)),
      started_(std::chrono::steady_clock::now()),
      echo_(std::make_unique<control_detail::EchoTaps>(gateway)) {}

ControlProtocol::~ControlProtocol() = default;

bool ControlProtocol::is_mutating(std::string_view command) {
  return command == "bind" || command == "replace" || command == "unbind" || command == "reload" ||
         command == "replay" || command == "replay_stop";
}

std::optional<std::string> ControlProtocol::handle(std::string_view request_line, const PeerCredentials& peer,
                                                   const Reply& later) {
  Answer response;
  const bool shallow = json_nesting_within(request_line, kMaxRequestNesting);
  const Json request = shallow ? Json::parse(request_line, nullptr, false) : Json(Json::value_t::discarded);
  if (!shallow) {
    response =
        failure("bad_request", "the request nests deeper than " + std::to_string(kMaxRequestNesting) + " levels");
  } else if (request.is_discarded() || !request.is_object()) {
    response = failure("bad_request", "the request is not a JSON object");
  } else if (!request.contains("command") || !request["command"].is_string()) {
    response = failure("bad_request", "the request has no \"command\" string");
  } else {
    try {
      response = dispatch(request, peer, later);
    } catch (const Json::exception& e) {
      response = failure("bad_request", std::string("malformed request: ") + e.what());
    } catch (const std::exception& e) {
      response = failure("internal_error", e.what());
    }
  }
  if (!response) return std::nullopt;
  return render(*response);
}

std::string ControlProtocol::handle(std::string_view request_line, const PeerCredentials& peer) {
  return *handle(request_line, peer, Reply{});  // no Reply: admission runs inline
}

// "denied #7: uid 1000 pid 4242": the number makes every line distinct, so a logger that folds
// repeated lines never hides one, and the pid says which process asked.
std::string ControlProtocol::next_log_tag(const char* kind, const PeerCredentials& peer) {
  return std::string(kind) + " #" + std::to_string(++log_sequence_) + ": uid " + std::to_string(peer.uid) + " pid " +
         std::to_string(peer.pid);
}

ControlProtocol::Answer ControlProtocol::dispatch(const Json& request, const PeerCredentials& peer,
                                                  const Reply& later) {
  const std::string command = request["command"].get<std::string>();
  const auto op = operators_.find(command);
  const bool mutating = is_mutating(command) || op != operators_.end();
  // A runner's report binds nothing, but can flag its FMU's channels violated: a permission of its own.
  const bool report = command == "fmu_report";
  if (!(report ? policy_.may_report(peer) : mutating ? policy_.may_modify(peer) : policy_.may_read(peer))) {
    if (const auto count = denials_.deny(peer.uid, command, std::chrono::steady_clock::now())) {
      std::string line = next_log_tag("denied", peer) + " may not run " + printable(command);
      if (*count > 1) {
        line += " (denial " + std::to_string(*count) + " of this command for uid " + std::to_string(peer.uid) +
                " in this burst; logged at powers of two)";
      }
      log_.log(LogLevel::warning, line);
    }
    return failure("permission_denied", std::string("uid ") + std::to_string(peer.uid) + " may not " +
                                            (report     ? std::string("report an FMU's state (fmu_report)")
                                             : mutating ? "change the gateway (" + command + ")"
                                                        : std::string("read gateway state")));
  }
  if (command == "status") return status();
  if (command == "segments") return segments();
  if (command == "channels") return channels();
  if (command == "channel") return channel(request);
  const auto now = std::chrono::steady_clock::now();
  if (report) return fmu_reports_.accept(request, gateway_.config().fmus, now);
  if (command == "fmus") return fmu_reports_.fmus_answer(gateway_.config().fmus, now);
  echo_->expire(now);
  if (command == "echo_open") return echo_->open(request, now);
  if (command == "echo_read") return echo_->read(request, now);
  if (command == "echo_close") return echo_->close(request);
  if (op != operators_.end()) return op->second(request);
  if (mutating) return mutate(command, request, peer, later);
  if (const auto reader = readers_.find(command); reader != readers_.end()) return reader->second();
  std::string known = "status, segments, channels, channel, fmus, fmu_report, echo_open, echo_read, echo_close";
  for (const auto& [name, answer] : readers_) known += ", " + name;
  for (const auto& [name, answer] : operators_) known += ", " + name;
  return failure("unknown_command", "unknown command '" + printable(command) + "' (" + known +
                                        ", bind, replace, unbind, reload, replay, replay_stop)");
}

ControlProtocol::Answer ControlProtocol::mutate(const std::string& command, const Json& request,
                                                const PeerCredentials& peer, const Reply& later) {
  std::string audit = next_log_tag("audit", peer) + " runs " + command;
  if (request.contains("name") && request["name"].is_string())
    audit += " " + printable(request["name"].get<std::string>());
  log_.log(LogLevel::notice, audit);
  if (admission_running()) {
    return failure("busy",
                   "an admission is running (" + running_ + "); " + command + " refused, try again when it finishes");
  }
  if (command == "bind" || command == "replace") return bind(request, command == "replace", later);
  if (command == "reload") return reload(later);
  if (command == "replay") return replay(request, later);
  if (command == "replay_stop") return stop_replay(request, later);
  return finish(command, request, unbind(request));
}

// A change that is active but could not be saved is not `ok`: it would be lost at restart.
Json ControlProtocol::finish(const std::string& command, const Json& request, Json answer) {
  if (!answer.value("ok", false) || !on_change_) return answer;
  const std::string error = on_change_(command, request);
  if (error.empty()) return answer;
  answer["ok"] = false;
  answer["error"] = {{"code", "not_persisted"},
                     {"message", "the change is active but was not saved and will not survive a restart: " + error}};
  return answer;
}

ControlProtocol::Answer ControlProtocol::run_admission(std::string what, std::function<void()> work,
                                                       std::function<Answer()> done, const Reply& later) {
  if (!offload_ || !later) {
    work();
    return done();
  }
  running_ = std::move(what);
  auto failed = std::make_shared<std::string>();
  auto guarded = [work = std::move(work), failed] {
    try {
      work();
    } catch (const std::exception& e) {
      *failed = e.what();
    }
  };
  offload_(std::move(guarded), [this, done = std::move(done), later, failed] {
    running_.clear();
    Answer answer;
    try {
      answer = failed->empty() ? done() : failure("internal_error", "admission failed: " + *failed);
    } catch (const std::exception& e) {
      answer = failure("internal_error", e.what());
    }
    if (answer) later(render(*answer));
  });
  return std::nullopt;
}

Json ControlProtocol::status() const {
  const Gateway::VerdictCounts counts = gateway_.verdict_counts();
  std::size_t up = 0;
  const auto segments = gateway_.segments();
  for (const auto& s : segments) up += s.health.state == SegmentHealth::up ? 1 : 0;
  const double uptime = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  char id[20];
  std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(gateway_.identity().id));
  return Json{{"ok", true},
              {"gateway", {{"name", gateway_.identity().name}, {"id", id}, {"uptime_s", uptime}}},
              {"segments", {{"total", segments.size()}, {"up", up}}},
              {"channels",
               {{"bound", counts.bound},
                {"degraded", counts.degraded},
                {"failed", counts.failed},
                {"violated", gateway_.violated_channels()}}},
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
               {"peers", s.peers},
               {"network", network_identity(s.spec)},
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
    for (const TransportCounter& c : s.adapter.transport) entry["adapter"][c.name] = c.value;
    for (const TransportNote& n : s.adapter.transport_notes) entry["adapter"][n.name] = n.text;
    if (s.spec.type == SegmentType::can) {
      entry["interface"] = s.spec.can.interface;
      entry["bitrate"] = s.spec.can.bitrate.bits_per_second;
      Json unexplained = Json::array();
      for (const UnexplainedFrames& f : s.adapter.unexplained) {
        unexplained.push_back({{"can_id", f.can_id},
                               {"id", can_id_text(f.can_id, f.extended)},
                               {"extended", f.extended},
                               {"frames", f.frames},
                               {"rate_hz", f.rate_hz}});
      }
      entry["unexplained"] = std::move(unexplained);
      entry["unexplained_others"] = s.adapter.unexplained_others;
    } else if (s.spec.type == SegmentType::dds) {
      entry["domain"] = s.spec.dds.domain;
    } else if (s.spec.type == SegmentType::replay) {
      entry["file"] = s.spec.replay.file;
      entry["speed"] = s.spec.replay.speed;
      entry["loop"] = s.spec.replay.loop;
      entry["run_time"] = replays_.count(s.spec.name) > 0;  // added by `replay`, ended by `replay_stop`
    } else {
      entry["url"] = s.spec.lcm.url;
    }
    list.push_back(std::move(entry));
  }
  return Json{{"ok", true}, {"segments", list}};
}

namespace {
// A hop whose transport refused remote endpoints for their QoS: they are there and exchange
// nothing with the gateway. On a publisher hop the gateway reads, so the refused are writers.
std::string incompatible_text(const HopReport& hop, std::uint64_t count) {
  const char* peer = hop.role == HopRole::publisher ? "writer" : "reader";
  return std::to_string(count) + " remote " + peer + (count == 1 ? "" : "s") + " on " + hop.segment +
         " refused for incompatible QoS (not matched; the log names the policy)";
}

// A remote endpoint that the far side refuses (or neither side accepts), with the rule.
std::string peer_conflict_text(const HopReport& hop, const PeerQosConflict& c) {
  return "remote " + c.peer + " " + c.id + " of " + c.topic + " on " + hop.segment + ": " + c.policy + ": " + c.reason;
}

// Predicted (admission) next to measured (the lane) for one egress hop.
Json hop_runtime(const HopReport& hop, const HopRuntimeSnapshot& measured) {
  return Json{{"predicted_latency_s", hop.latency ? Json(to_seconds(*hop.latency)) : Json(nullptr)},
              {"events", measured.events},
              {"residence_p50_s", to_seconds(measured.residence_p50)},
              {"residence_p99_s", to_seconds(measured.residence_p99)},
              {"residence_p999_s", to_seconds(measured.residence_p999)},
              {"residence_max_s", to_seconds(measured.residence_max)},
              {"residence_miss", measured.residence_miss},
              {"deadline_miss", measured.deadline_miss}};
}
}  // namespace

Json ControlProtocol::channel_entry(const ChannelReport& verdict, const ChannelStatsSnapshot* stats) const {
  const ChannelSpec* spec = gateway_.knowledge_base().find_bound(verdict.name);
  Json entry{{"name", verdict.name},
             {"class", to_string(verdict.cls)},
             {"verdict", to_string(verdict.verdict)},
             {"reasons", verdict.reasons},
             {"segments", Json::array()}};
  if (spec) {
    char subject[24];
    std::snprintf(subject, sizeof subject, "0x%016llx", static_cast<unsigned long long>(spec->subject));
    entry["subject"] = subject;
    // The contents' type (cosmic/channel_type.hpp) as text; null: opaque bytes.
    entry["type"] = spec->type ? Json(describe(*spec->type)) : Json(nullptr);
  }
  if (const auto etag = gateway_.knowledge_base().etag_of(verdict.name)) entry["etag"] = *etag;
  entry["mismatches"] = Json::array();
  for (const auto& hop : verdict.hops) {
    Json seg{
        {"segment", hop.segment}, {"role", to_string(hop.role)}, {"rx", 0}, {"tx", 0}, {"dropped", Json::object()}};
    const auto matched = gateway_.matched_peers(hop.segment, verdict.name);
    seg["matched"] = matched ? Json(*matched) : Json(nullptr);
    const auto incompatible = gateway_.incompatible_peers(hop.segment, verdict.name);
    seg["incompatible"] = incompatible ? Json(*incompatible) : Json(nullptr);
    if (incompatible && *incompatible > 0) entry["mismatches"].push_back(incompatible_text(hop, *incompatible));
    // Where the transport has discovery: the remote endpoints the far side refuses by rules
    // the transport's own matching does not report (`matched` may count them).
    if (matched) {
      seg["peer_conflicts"] = Json::array();
      for (const PeerQosConflict& c : gateway_.peer_qos_conflicts(hop.segment, verdict.name)) {
        seg["peer_conflicts"].push_back(
            {{"peer", c.peer}, {"id", c.id}, {"topic", c.topic}, {"policy", c.policy}, {"reason", c.reason}});
        entry["mismatches"].push_back(peer_conflict_text(hop, c));
      }
    } else {
      seg["peer_conflicts"] = nullptr;
    }
    // A typed channel's form on the hop as routed; null for an untyped channel (its contents cross
    // as the bytes they came in).
    const std::optional<std::string> form = gateway_.hop_form(verdict.name, hop.segment);
    seg["representation"] = form ? Json(*form) : Json(nullptr);
    for (std::size_t r = 0; r < kDropReasonCount; ++r) seg["dropped"][to_string(static_cast<DropReason>(r))] = 0;
    seg["omitted"] = 0;
    seg["omission_excess"] = 0;
    if (stats) {
      for (const auto& counters : stats->segments) {
        if (counters.segment != hop.segment) continue;
        seg["rx"] = counters.rx;
        seg["tx"] = counters.tx;
        for (std::size_t r = 0; r < kDropReasonCount; ++r) {
          seg["dropped"][to_string(static_cast<DropReason>(r))] = counters.dropped[r];
        }
        seg["omitted"] = counters.omitted;
        seg["omission_excess"] = counters.omission_excess;
        if (counters.egress && hop.role == HopRole::subscriber) seg["runtime"] = hop_runtime(hop, *counters.egress);
      }
    }
    entry["segments"].push_back(std::move(seg));
  }
  entry["forwarded"] = stats ? stats->forwarded : 0;
  entry["residence"] = {{"p50_s", stats ? to_seconds(stats->residence_p50) : 0.0},
                        {"p99_s", stats ? to_seconds(stats->residence_p99) : 0.0},
                        {"p999_s", stats ? to_seconds(stats->residence_p999) : 0.0},
                        {"max_s", stats ? to_seconds(stats->residence_max) : 0.0},
                        {"bound_s", to_seconds(gateway_.config().gateway.residence_bound)}};
  entry["runtime_state"] = to_string(stats ? stats->runtime_state : RuntimeState::bound);
  entry["violations"] = stats ? stats->violations : 0;
  entry["residence_miss"] = stats ? stats->residence_miss : 0;
  entry["deadline_miss"] = stats ? stats->deadline_miss : 0;
  if (verdict.end_to_end.latency) entry["predicted_end_to_end_s"] = to_seconds(*verdict.end_to_end.latency);
  if (verdict.end_to_end.reaction_time) entry["reaction_time_s"] = to_seconds(*verdict.end_to_end.reaction_time);
  entry["fmus"] = fmu_reports_.channel_part(verdict.name, gateway_.config().fmus, std::chrono::steady_clock::now());
  return entry;
}

Json ControlProtocol::channels() const {
  const auto stats = gateway_.channel_stats();
  Json list = Json::array();
  for (const auto& verdict : gateway_.admission().channels)
    list.push_back(channel_entry(verdict, find_stats(stats, verdict.name)));
  return Json{{"ok", true}, {"channels", list}};
}

// Why `name` is not bound: admission rejected it when the configuration was loaded, or no such channel.
Json ControlProtocol::unbound_channel(const std::string& name) const {
  const ChannelReport* rejected = gateway_.rejected_at_load(name);
  if (!rejected) return failure("not_found", "no bound channel named '" + name + "'");
  std::string reasons;
  for (const auto& r : rejected->reasons) reasons += (reasons.empty() ? "" : "; ") + r;
  Json out = failure(
      "rejected", "channel '" + name + "' of the configuration is not bound: admission rejected it (" + reasons + ")");
  out["error"]["reasons"] = rejected->reasons;
  out["error"]["admission"] = to_json(*rejected);
  return out;
}

Json ControlProtocol::channel(const Json& request) const {
  if (!request.contains("name") || !request["name"].is_string())
    return failure("bad_request", "\"name\" (string) is required");
  const std::string name = request["name"].get<std::string>();
  const AdmissionReport report = gateway_.admission();
  const ChannelReport* verdict = report.find(name);
  if (!verdict) return unbound_channel(name);
  const auto stats = gateway_.channel_stats();
  Json entry = channel_entry(*verdict, find_stats(stats, name));
  entry["admission"] = to_json(*verdict);
  return Json{{"ok", true}, {"channel", entry}};
}

ControlProtocol::Answer ControlProtocol::bind(const Json& request, bool replace, const Reply& later) {
  if (!request.contains("yaml") || !request["yaml"].is_string()) {
    return failure("bad_request", "\"yaml\" (string with channel definitions) is required");
  }
  const std::string file =
      request.contains("file") && request["file"].is_string() ? request["file"].get<std::string>() : "request";
  ChannelsResult parsed = parse_channels(request["yaml"].get<std::string>(), file, gateway_.config());
  if (!parsed.ok()) {
    Json out = failure("config_error", std::to_string(parsed.errors.size()) + " error(s) in the channel definitions");
    out["errors"] = to_json(parsed.errors);
    return out;
  }
  // A run-time replay is not saved: a saved definition naming its segment would not bind at the
  // next start (and would take the channel's file definition with it).
  for (const auto& c : parsed.channels) {
    if (const std::string replay = run_time_replay_in(c); !replay.empty()) {
      return failure("replay_failed", "channel " + c.name + " names " + replay +
                                          ", a run-time replay's segment; nothing changed (cosmicctl replay and "
                                          "replay stop " +
                                          replay + " handle it)");
    }
  }
  if (replace) {
    if (auto bad = bad_match_timeout(request)) return bad;
    // A replacement of something not bound is most likely a wrong name: binding it would leave
    // the channel meant to be replaced running as it was.
    std::string unbound;
    for (const auto& c : parsed.channels) {
      if (!gateway_.knowledge_base().find_bound(c.name)) unbound += (unbound.empty() ? "'" : ", '") + c.name + "'";
    }
    if (!unbound.empty()) {
      return failure("not_found", "no bound channel named " + unbound +
                                      " to replace; nothing changed (bind a new channel without --replace)");
    }
  }
  const std::string command = replace ? "replace" : "bind";
  const std::string what = command + " of " + names_of(parsed.channels);
  auto plan = std::make_shared<BindPlan>(replace ? gateway_.replace_plan_input(std::move(parsed.channels))
                                                 : gateway_.bind_plan_input(std::move(parsed.channels)));
  const bool gated = gate_ && offload_ && later;
  return run_admission(
      what, [plan] { replace_or_bind(*plan); },
      [this, plan, request, command, gated, what, later]() -> Answer {
        if (!gated || !plan->admitted) return conclude(plan, request, command, false, later);
        running_ = what + " (claiming the federation's shared networks)";
        try {
          gate_(*plan, [this, plan, request, command, later] {
            running_.clear();
            Answer answer;
            try {
              answer = conclude(plan, request, command, true, later);
            } catch (const std::exception& e) {
              answer = failure("internal_error", e.what());
            }
            if (answer) later(render(*answer));
          });
        } catch (const std::exception& e) {
          running_.clear();  // never left busy by a gate that failed
          return failure("internal_error", std::string("claiming the networks failed: ") + e.what());
        }
        return std::nullopt;
      },
      later);
}

ControlProtocol::Answer ControlProtocol::conclude(std::shared_ptr<BindPlan> plan, const Json& request,
                                                  const std::string& command, bool replan, const Reply& later) {
  if (plan->replacing) return switch_planned(std::move(plan), request, command, replan, later);
  return commit_planned(std::move(*plan), request, command, replan);
}

Json ControlProtocol::commit_planned(BindPlan plan, const Json& request, const std::string& command, bool replan) {
  if (replan && plan.generation != gateway_.generation()) {
    // Other gateways' reservations (or claims) changed while the bind waited: admit it again, here
    // on the control thread, against what is known now (an incremental admission: milliseconds for
    // hundreds of channels; status answers wait that long).
    BindPlan fresh = gateway_.bind_plan_input(plan.channels);
    Gateway::plan_bind(fresh);
    plan = std::move(fresh);
  }
  const BindResult result = gateway_.commit_bind(std::move(plan));
  Json answer = bind_answer(result);
  return finish(command, request, std::move(answer));
}

Json ControlProtocol::unbind(const Json& request) {
  if (!request.contains("name") || !request["name"].is_string())
    return failure("bad_request", "\"name\" (string) is required");
  const std::string name = request["name"].get<std::string>();
  if (!gateway_.unbind(name)) return failure("not_found", "no bound channel named '" + name + "'");
  return Json{{"ok", true}, {"unbound", name}};
}

std::optional<nlohmann::json> ControlProtocol::bad_match_timeout(const Json& request) const {
  if (!request.contains("match_timeout_s")) return std::nullopt;
  const Json& timeout = request["match_timeout_s"];
  if (timeout.is_number() && timeout.get<double>() >= 0 && timeout.get<double>() <= kMaxMatchTimeoutS)
    return std::nullopt;
  return failure("bad_request", "\"match_timeout_s\" must be a number of seconds from 0 to " +
                                    std::to_string(static_cast<int>(kMaxMatchTimeoutS)) + "; nothing changed");
}

// Loading the file and admission both run off the control thread; the swap runs on it.
ControlProtocol::Answer ControlProtocol::reload(const Reply& later) {
  auto loaded = std::make_shared<ConfigResult>();
  auto plan = std::make_shared<ReloadPlan>();
  // Channels unchanged since the running bindings were admitted are not admitted again.
  auto work = [this, loaded, plan, base = gateway_.reload_base(),
               peers = gateway_.knowledge_base().peer_reservations()] {
    *loaded = reload_source_();
    if (loaded->ok()) *plan = Gateway::plan_reload(loaded->config, base, peers);
  };
  auto done = [this, loaded, plan] {
    if (!loaded->ok()) {
      Json out = failure("config_error", std::to_string(loaded->errors.size()) +
                                             " error(s) in the configuration; the running configuration is unchanged");
      out["errors"] = to_json(loaded->errors);
      return out;
    }
    const BindResult result = gateway_.commit_reload(std::move(*plan));
    if (result.applied) {
      replays_.clear();                                      // their segments went with the running configuration
      fmu_reports_.keep_configured(gateway_.config().fmus);  // and the reports of FMUs it no longer has
    }
    Json out = bind_answer(result);
    if (!result.applied) out["error"] = {{"code", "reload_failed"}, {"message", result.error}};
    return finish("reload", Json{{"command", "reload"}}, std::move(out));
  };
  return run_admission("reload", std::move(work), std::move(done), later);
}

}  // namespace cosmic

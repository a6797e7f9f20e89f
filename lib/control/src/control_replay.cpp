// Run-time replays (docs/control-protocol.md, `replay` and `replay_stop`; issue 37): a recording
// played into running channels in place of their publishers, or beside them, and taken out again.
// The segment comes from the configuration's reader (the recording read and scanned off the
// control thread, as a reload reads it), the swap is a replacement made before break, admitted as
// any other. Control thread only.
#include <algorithm>
#include <filesystem>

#include "cosmic/control_protocol.hpp"
#include "cosmic/report.hpp"

#include "bind_answer.hpp"

namespace cosmic {

using Json = nlohmann::json;

namespace {

bool names(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

// `channel` with `publishers`, less what belonged to the publishers it loses (their native
// bindings and SecOC), as YAML the configuration's reader takes again (which derives each hop's form).
std::string with_publishers(ChannelSpec channel, std::vector<std::string> publishers) {
  channel.publishers = std::move(publishers);
  const auto dropped = [&](const std::string& segment) {
    return !names(channel.publishers, segment) && !names(channel.subscribers, segment);
  };
  std::erase_if(channel.native, [&](const NativeBinding& n) { return dropped(n.segment); });
  std::erase_if(channel.secoc, [&](const SecocSpec& s) { return dropped(s.segment); });
  return "- " + channel_to_yaml(channel) + "\n";
}

std::string quoted_list(const std::vector<std::string>& list) {
  std::string out;
  for (const auto& item : list) out += (out.empty() ? "'" : ", '") + item + "'";
  return out;
}

}  // namespace

std::string ControlProtocol::run_time_replay_in(const ChannelSpec& channel) const {
  for (const auto& [name, replay] : replays_)
    if (names(channel.publishers, name) || names(channel.subscribers, name)) return name;
  return {};
}

void ControlProtocol::drop_segment(RunTimeReplay replay) {
  if (const Result<void> removed = gateway_.remove_segment(replay.name); !removed) {
    log_.log(LogLevel::error, "replay " + replay.name + ": its segment stays: " + removed.error().text +
                                  " (replay stop " + replay.name + " removes it later)");
    replay.before.clear();
    replay.replayed.clear();
    replays_[replay.name] = std::move(replay);
  }
}

void ControlProtocol::abandon_replay() {
  if (!pending_replay_) return;
  RunTimeReplay replay = std::move(*pending_replay_);
  pending_replay_.reset();
  if (replays_.count(replay.name) == 0) drop_segment(std::move(replay));
}

ControlProtocol::Answer ControlProtocol::replay(const Json& request, const Reply& later) {
  if (!request.contains("segment") || !request["segment"].is_object()) {
    return failure("bad_request",
                   "\"segment\" (an object: file, and optionally name, channels, speed, loop, "
                   "start_offset, realtime, latency_bound) is required");
  }
  Json segment = request["segment"];
  if (!segment.contains("type")) segment["type"] = "replay";
  if (segment["type"] != "replay") return failure("bad_request", "a segment added at run time is of type replay");
  if (!segment.contains("file") || !segment["file"].is_string() ||
      !std::filesystem::path(segment["file"].get<std::string>()).is_absolute()) {
    return failure("bad_request", "\"segment.file\" must be the recording's absolute path");
  }
  if (!segment.contains("name")) {
    for (int n = 1;; ++n) {
      const std::string name = "replay-" + std::to_string(n);
      if (!gateway_.config().find_segment(name)) {
        segment["name"] = name;
        break;
      }
    }
  }
  const Json mode = request.contains("mode") ? request["mode"] : Json("replace");
  if (mode != "replace" && mode != "alongside")
    return failure("bad_request", "\"mode\" is \"replace\" (the default) or \"alongside\"");
  if (auto bad = bad_match_timeout(request)) return bad;
  auto parsed = std::make_shared<SegmentResult>();
  auto work = [parsed, text = segment.dump(), running = gateway_.config()] {
    *parsed = parse_segment(text, "request", running);
  };
  auto done = [this, parsed, request, later]() -> Answer {
    if (!parsed->ok()) {
      Json out = failure("config_error", std::to_string(parsed->errors.size()) + " error(s) in the replay segment");
      out["errors"] = to_json(parsed->errors);
      return out;
    }
    return begin_replay(std::move(parsed->segment), request, later);
  };
  return run_admission("replay of " + segment["file"].get<std::string>(), std::move(work), std::move(done), later);
}

ControlProtocol::Answer ControlProtocol::begin_replay(SegmentSpec segment, const Json& request, const Reply& later) {
  RunTimeReplay replay{segment.name, segment.replay.file, {}, {}};
  std::vector<std::string> unbound;
  for (const ReplayStream& stream : segment.replay.streams) {
    if (const ChannelSpec* bound = gateway_.knowledge_base().find_bound(stream.channel)) {
      replay.before.push_back(*bound);
    } else {
      unbound.push_back(stream.channel);
    }
  }
  if (!unbound.empty()) {
    return failure("not_found", "the recording's channel(s) " + quoted_list(unbound) +
                                    " are not bound here; nothing changed (select the channels to replay)");
  }
  // One replay per channel at a time: the definition a stop puts back must name live segments only.
  for (const ChannelSpec& channel : replay.before) {
    if (const std::string other = run_time_replay_in(channel); !other.empty()) {
      return failure("replay_failed", "channel " + channel.name + " is being replayed by " + other +
                                          "; nothing changed (cosmicctl replay stop " + other + " first)");
    }
  }
  const bool alongside = request.contains("mode") && request["mode"] == "alongside";  // checked by replay()
  std::string yaml;
  for (const ChannelSpec& channel : replay.before) {
    std::vector<std::string> publishers{segment.name};
    if (alongside) publishers.insert(publishers.begin(), channel.publishers.begin(), channel.publishers.end());
    yaml += with_publishers(channel, std::move(publishers));
  }
  if (const Result<void> added = gateway_.add_segment(segment); !added) {
    return failure("replay_failed", added.error().text + "; nothing changed");
  }
  ChannelsResult channels = parse_channels(yaml, "replay", gateway_.config());
  if (!channels.ok()) {
    static_cast<void>(gateway_.remove_segment(segment.name));  // carries nothing yet: always removable
    return failure("replay_failed", "the replayed definitions do not read: " + channels.errors.front().to_string() +
                                        "; nothing changed");
  }
  replay.replayed = channels.channels;
  auto plan = std::make_shared<BindPlan>(gateway_.replace_plan_input(std::move(channels.channels)));
  Gateway::plan_replace(*plan);
  pending_replay_ = std::move(replay);
  return conclude(std::move(plan), request, "replay", false, later);
}

ControlProtocol::Answer ControlProtocol::stop_replay(const Json& request, const Reply& later) {
  if (!request.contains("name") || !request["name"].is_string())
    return failure("bad_request", "\"name\" (the replay segment's) is required");
  const std::string name = request["name"].get<std::string>();
  const auto found = replays_.find(name);
  if (found == replays_.end()) {
    std::vector<std::string> running;
    for (const auto& [n, r] : replays_) running.push_back(n);
    return failure("not_found", "no run-time replay named '" + name + "' (running: " +
                                    (running.empty() ? std::string("none") : quoted_list(running)) + ")");
  }
  const RunTimeReplay& replay = found->second;
  std::string yaml;
  for (const ChannelSpec& before : replay.before) {
    const ChannelSpec* now = gateway_.knowledge_base().find_bound(before.name);
    if (!now || !names(now->publishers, name)) continue;  // unbound or rebound since: nothing of the replay's left
    const auto replayed = std::find_if(replay.replayed.begin(), replay.replayed.end(),
                                       [&](const ChannelSpec& r) { return r.name == before.name; });
    // As the replay left it: back to what it was. Changed since: only the replay's hop goes, and
    // the channel's own publishers come back where none is left, with their native bindings and SecOC.
    if (replayed != replay.replayed.end() && *replayed == *now) {
      yaml += with_publishers(before, before.publishers);
      continue;
    }
    ChannelSpec restored = *now;
    std::erase(restored.publishers, name);
    if (restored.publishers.empty()) {
      restored.publishers = before.publishers;
      for (const NativeBinding& n : before.native)
        if (names(before.publishers, n.segment) && !restored.native_on(n.segment)) restored.native.push_back(n);
      for (const SecocSpec& c : before.secoc)
        if (names(before.publishers, c.segment) && !restored.secoc_on(c.segment)) restored.secoc.push_back(c);
    }
    yaml += with_publishers(restored, restored.publishers);
  }
  pending_replay_ = replay;
  if (yaml.empty()) {
    BindResult nothing;
    nothing.applied = true;
    Json answer = bind_answer(nothing);
    settle_replay("replay_stop", nothing, answer);
    return finish("replay_stop", request, std::move(answer));
  }
  ChannelsResult channels = parse_channels(yaml, "replay_stop", gateway_.config());
  if (!channels.ok()) {
    pending_replay_.reset();
    return failure("replay_failed", "the restored definitions do not read: " + channels.errors.front().to_string() +
                                        "; nothing changed");
  }
  auto plan = std::make_shared<BindPlan>(gateway_.replace_plan_input(std::move(channels.channels)));
  Gateway::plan_replace(*plan);
  return conclude(std::move(plan), request, "replay_stop", false, later);
}

void ControlProtocol::settle_replay(const std::string& command, const BindResult& result, Json& answer) {
  if ((command != "replay" && command != "replay_stop") || !pending_replay_) return;
  RunTimeReplay replay = std::move(*pending_replay_);
  pending_replay_.reset();
  const std::string name = replay.name;
  Json summary{{"name", name}, {"file", replay.file}, {"channels", Json::array()}};
  for (const ChannelSpec& c : replay.before) summary["channels"].push_back(c.name);
  if (command == "replay") {
    // The recording's numbers answer a rejection too: they say why the replay's rate did not fit.
    if (const SegmentSpec* segment = gateway_.config().find_segment(name)) {
      summary["speed"] = segment->replay.speed;
      summary["loop"] = segment->replay.loop;
      summary["start_offset_ns"] = segment->replay.start_offset.count();
      Json streams = Json::array();
      for (const ReplayStream& s : segment->replay.streams)
        streams.push_back({{"channel", s.channel}, {"events", s.events}, {"tightest_ns", s.tightest.count()}});
      summary["streams"] = std::move(streams);
    }
    if (result.applied) {
      replays_[name] = std::move(replay);
    } else {
      drop_segment(std::move(replay));  // never carried a channel
    }
  } else if (result.applied) {
    if (const Result<void> removed = gateway_.remove_segment(name); !removed) {
      // Kept under its name with nothing to restore: a later replay_stop removes it.
      summary["segment_kept"] = removed.error().text;
      replay.before.clear();
      replay.replayed.clear();
      replays_[name] = std::move(replay);
    } else {
      replays_.erase(name);
    }
  } else if (answer.contains("error")) {
    answer["error"]["message"] = answer["error"].value("message", std::string()) +
                                 "; the replay runs on: change the channel with bind --replace or unbind it, then "
                                 "replay stop " +
                                 name + " removes the segment";
  }
  answer["replay"] = std::move(summary);
}

}  // namespace cosmic

// cosmicd's recording (recording_service.hpp).
#include "recording_service.hpp"

#include <cstdio>

namespace cosmicd {
namespace {

using Json = nlohmann::json;

Json failure(const std::string& code, const std::string& message) {
  return Json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}};
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& name : names) out += (out.empty() ? "" : ",") + name;
  return out;
}

// What a reader of the file should know of the channel's contract (MCAP channel metadata).
cosmic::McapMap contract_of(const cosmic::ChannelSpec& spec) {
  char subject[24];
  std::snprintf(subject, sizeof subject, "0x%llx", static_cast<unsigned long long>(spec.subject));
  cosmic::McapMap out{{"subject", subject},
                      {"class", cosmic::to_string(spec.cls)},
                      {"payload_bytes", std::to_string(spec.payload)},
                      {"publishers", joined(spec.publishers)},
                      {"subscribers", joined(spec.subscribers)}};
  if (spec.period) out["period"] = cosmic::format_duration(*spec.period);
  if (spec.type) out["type"] = cosmic::describe(*spec.type);
  return out;
}

}  // namespace

void RecordingService::configure(cosmic::Gateway& gateway, const cosmic::Config& config) {
  gateway_ = &gateway;
  const cosmic::RecordingSpec& next = config.recording;
  const bool added = next.enabled() && !spec_.enabled();
  std::map<std::string, std::string> interfaces;
  for (const cosmic::SegmentSpec& segment : config.segments) {
    if (segment.type == cosmic::SegmentType::can) interfaces[segment.name] = segment.can.interface;
  }
  const bool changed = next != spec_ || (!next.candump.empty() && interfaces != interfaces_);
  spec_ = next;
  interfaces_ = std::move(interfaces);
  if (!spec_.enabled()) {
    if (recording_) stop();
    return;
  }
  if (!recorder_) {
    recorder_ = std::make_unique<cosmic::Recorder>(spec_, config.gateway.name, log_);
    gateway.set_recording(recorder_.get(), {}, [this](const std::vector<cosmic::Route>& routes) { on_routes(routes); });
  } else if (changed) {
    recorder_->reconfigure(spec_);
    // The routes were applied before this new section was known (a reload): the recorder's table
    // must hold the channels the new selection takes.
    on_routes(last_routes_);
  }
  if (!candump_ && !spec_.candump.empty()) {
    candump_ = std::make_unique<cosmic::CandumpRecorder>(spec_, config.gateway.name, log_);
  } else if (candump_ && changed) {
    candump_->reconfigure(spec_);
  }
  if (added && spec_.start) {
    if (const Json answer = start(); !answer.value("ok", false))
      log_.log(cosmic::LogLevel::error, "recording did not start: " + answer["error"].value("message", ""));
    return;
  }
  if (recording_ && changed) {
    // The new directory, compression and rotation from a new file on, the new selection now.
    stop_both();
    select(true);
    if (auto started = start_both(); !started) {
      recording_ = false;
      select(false);
      log_.log(cosmic::LogLevel::error, "recording stopped: " + started.error().text);
    }
  }
}

void RecordingService::on_routes(const std::vector<cosmic::Route>& routes) {
  if (&routes != &last_routes_) last_routes_ = routes;
  std::vector<cosmic::RecordedChannel> channels;
  std::vector<std::string> segments;
  for (const cosmic::Route& route : routes) {
    for (std::size_t i = 0; i < route.publishers.size() && i < route.spec.publishers.size(); ++i) {
      if (segments.size() <= route.publishers[i]) segments.resize(route.publishers[i] + 1);
      segments[route.publishers[i]] = route.spec.publishers[i];
    }
    if (!spec_.selects(route.spec.name)) continue;
    cosmic::RecordedChannel channel;
    channel.id = route.id;
    channel.name = route.spec.name;
    channel.metadata = contract_of(route.spec);
    if (route.spec.type) {
      const auto why_not = cosmic::set_typed_encoding(channel, *route.spec.type, spec_.typed_encoding);
      // Said once per channel and reason, not at every rebind or reload that keeps the type.
      if (why_not && warned_json_.insert(channel.name + '\n' + *why_not).second) {
        log_.log(cosmic::LogLevel::warning, "recording: channel " + channel.name +
                                                " is recorded as JSON, not CDR (typed_encoding: cdr): " + *why_not);
      }
    }
    channels.push_back(std::move(channel));
  }
  recorder_->set_channels(std::move(channels));
  recorder_->set_segment_names(std::move(segments));
}

void RecordingService::select(bool recording) {
  if (!gateway_) return;
  if (!recording) {
    gateway_->select_recorded({});
    return;
  }
  gateway_->select_recorded([spec = spec_](const cosmic::ChannelSpec& channel) { return spec.selects(channel.name); });
}

Json RecordingService::start() {
  if (!recorder_ || !spec_.enabled())
    return failure("not_configured", "the configuration has no recording section (recording: {directory: ...})");
  if (recording_) return status();
  // Files first, then the selection: no event is taken before a file can hold it.
  if (auto started = start_both(); !started) return failure("record_failed", started.error().text);
  recording_ = true;
  select(true);
  return status();
}

Json RecordingService::stop() {
  if (!recorder_ || !recording_) return status();
  select(false);
  stop_both();
  recording_ = false;
  log_.log(cosmic::LogLevel::notice, "recording stopped");
  return status();
}

cosmic::Result<void> RecordingService::start_both() {
  if (auto started = recorder_->start(); !started) return started;
  if (candump_ && !spec_.candump.empty()) {
    if (auto started = candump_->start(candump_segments()); !started) {
      recorder_->stop();
      return started;
    }
  }
  return {};
}

void RecordingService::stop_both() {
  if (candump_) candump_->stop();
  recorder_->stop();
}

std::vector<cosmic::CandumpSegment> RecordingService::candump_segments() {
  std::vector<cosmic::CandumpSegment> out;
  for (const std::string& name : spec_.candump) {
    auto tap = taps_.try_emplace(name, std::make_shared<cosmic::CandumpTap>()).first->second;
    const auto interface = interfaces_.find(name);
    out.push_back({name, interface != interfaces_.end() ? interface->second : name, std::move(tap)});
  }
  return out;
}

std::shared_ptr<cosmic::WireTap> RecordingService::wire_tap(const cosmic::SegmentSpec& segment) {
  if (segment.type != cosmic::SegmentType::can) return nullptr;
  return taps_.try_emplace(segment.name, std::make_shared<cosmic::CandumpTap>()).first->second;
}

void RecordingService::shut_down() {
  if (recording_) stop();
}

Json RecordingService::status() const {
  if (!recorder_) return Json{{"ok", true}, {"recording", {{"configured", false}, {"active", false}}}};
  const cosmic::RecorderStatus s = recorder_->status();
  Json candump = Json{{"segments", spec_.candump}, {"active", false}, {"files", 0}, {"lines", 0}, {"dropped", 0}};
  if (candump_) {
    const cosmic::CandumpStatus c = candump_->status();
    candump = Json{{"segments", spec_.candump},
                   {"active", c.recording},
                   {"files_open", c.files_open},
                   {"files", c.files},
                   {"lines", c.lines},
                   {"bytes", c.bytes},
                   {"dropped", c.dropped_full + c.dropped_failed},
                   {"dropped_queue_full", c.dropped_full},
                   {"dropped_not_written", c.dropped_failed},
                   {"last_error", c.last_error}};
  }
  const double ratio = s.compressed > 0 ? static_cast<double>(s.uncompressed) / static_cast<double>(s.compressed) : 0;
  return Json{{"ok", true},
              {"recording",
               {{"configured", spec_.enabled()},
                {"active", s.recording},
                {"directory", s.directory},
                {"file", s.file},
                {"channels", spec_.channels.empty() ? Json::array({"*"}) : Json(spec_.channels)},
                {"files", s.files},
                {"messages", s.messages},
                {"bytes", s.bytes},
                {"compression_ratio", ratio},
                {"record_dropped",
                 {{"queue_full", s.dropped_full}, {"not_written", s.dropped_failed}, {"invalid", s.dropped_invalid}}},
                {"queue_bytes", s.queue_bytes},
                {"queued_bytes", s.queued_bytes},
                {"last_error", s.last_error},
                {"candump", std::move(candump)}}}};
}

}  // namespace cosmicd

// What the running gateway shows (the other half of gateway.cpp, which starts, binds and reloads):
// health, channel statistics, run-time violations and their reasons, peers and segments.
#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cosmic/can_interference.hpp"
#include "cosmic/gateway.hpp"

namespace cosmic {

void Gateway::refresh_health() {
  for (const auto& [name, slot] : slots_) {
    HealthReport health = slot.adapter->health();
    kb_->set_health(name, health.state, std::move(health.detail));
  }
}

std::vector<ChannelStatsSnapshot> Gateway::channel_stats() const {
  std::vector<ChannelStatsSnapshot> stats = router_->snapshot();
  for (auto& channel : stats) {
    const auto track = runtime_.find(channel.name);
    if (track == runtime_.end()) continue;
    channel.runtime_state = track->second.state;
    channel.violations = track->second.violations;
  }
  return stats;
}

std::map<std::string, std::string> Gateway::undeclared_interference() const {
  std::map<std::string, std::string> out;
  std::optional<AdmissionReport> report;  // built only when a bus shows unexplained frames
  for (const auto& spec : config_.segments) {
    const auto slot = slots_.find(spec.name);
    if (spec.type != SegmentType::can || slot == slots_.end()) continue;
    const AdapterStatistics stats = slot->second.adapter->statistics();
    if (std::none_of(stats.unexplained.begin(), stats.unexplained.end(), [](const auto& f) { return f.rate_hz > 0; }))
      continue;
    if (!report) report = kb_->report();
    out.merge(cosmic::undeclared_interference(*report, spec.name, stats.unexplained));
  }
  return out;
}

void Gateway::refresh_runtime(Nanos now) {
  std::map<std::string, RuntimeTrack> next;
  const std::map<std::string, std::string> foreign = undeclared_interference();
  auto judge_bound = [&](const ChannelMisses& counted) {
    const ChannelSpec* spec = kb_->find_bound(counted.name);
    if (spec == nullptr || next.count(counted.name)) return;  // unbound since: its track ends
    const auto previous = runtime_.find(counted.name);
    RuntimeTrack track = previous != runtime_.end() ? previous->second : RuntimeTrack{};
    const auto reason = foreign.find(counted.name);
    const auto reported = reported_.find(counted.name);
    judge(counted, *spec, track, now, reason == foreign.end() ? nullptr : &reason->second,
          reported == reported_.end() ? nullptr : &reported->second);
    next.emplace(counted.name, track);
  };
  // Only channels that ever missed are tracked (every other one is `bound` at run time).
  for (const auto& counted : router_->misses()) judge_bound(counted);
  for (const auto& [name, reason] : foreign) judge_bound(ChannelMisses{name, 0, 0});
  for (const auto& [name, reason] : reported_) judge_bound(ChannelMisses{name, 0, 0});
  // A tracked channel the router reports no miss for any more (its route was applied afresh) is
  // judged with zero counts: a violation still ends only after a clean interval.
  for (const auto& [name, track] : runtime_) {
    if (next.count(name) == 0) judge_bound(ChannelMisses{name, 0, 0});
  }
  runtime_ = std::move(next);
}

// One channel: a new miss of an HRT hop, a gap in an end-to-end counter longer than the
// channel's omission degree, or a reported reason (any class: every class declares its omission
// degree, and an FMU publishing it promised its step) starts (or extends) a violation episode; a
// clean interval ends it. SRT and NRT channels count timing misses but keep their state (they were
// promised no bound).
void Gateway::judge(const ChannelMisses& counted, const ChannelSpec& spec, RuntimeTrack& track, Nanos now,
                    const std::string* foreign, const std::string* reported) {
  const std::uint64_t misses = counted.residence_miss + counted.deadline_miss;
  const bool late = spec.cls == ChannelClass::hrt && (misses > track.misses || foreign);
  const bool omitted = counted.omission_excess > track.omission_excess;
  const bool missed = late || omitted || reported;
  if (misses > track.misses || foreign || omitted || reported) track.last_miss = now;
  track.misses = misses;
  track.omission_excess = counted.omission_excess;
  if (missed && track.state == RuntimeState::bound) {
    track.state = RuntimeState::violated;
    ++track.violations;
    const std::string violated = "channel " + spec.name + " violated its admitted bounds: ";
    std::string line = late && foreign ? violated + *foreign
                       : late          ? violation_line(spec)
                       : reported      ? violated + *reported
                                       : omission_line(spec);
    log_.log(LogLevel::warning, line);
  } else if (!missed && track.state == RuntimeState::violated &&
             now - track.last_miss >= config_.gateway.clean_interval) {
    track.state = RuntimeState::bound;
    log_.log(LogLevel::notice, "channel " + spec.name + " is within its admitted bounds again (no miss for " +
                                   format_duration(config_.gateway.clean_interval) + ")");
  }
}

// The numbers behind a violation, hop by hop (once per episode: a full snapshot is fine here).
std::string Gateway::violation_line(const ChannelSpec& spec) const {
  std::string line = "channel " + spec.name + " violated its admitted bounds:";
  for (const auto& stats : router_->snapshot()) {
    if (stats.name != spec.name) continue;
    for (const auto& seg : stats.segments) {
      if (!seg.egress || (seg.egress->residence_miss == 0 && seg.egress->deadline_miss == 0)) continue;
      line += " hop " + seg.segment + ": residence max " + format_duration(seg.egress->residence_max) + " > bound " +
              format_duration(config_.gateway.residence_bound) + " (" + std::to_string(seg.egress->residence_miss) +
              " misses), " + std::to_string(seg.egress->deadline_miss) + " events older than reaction_time " +
              (spec.reaction_time ? format_duration(*spec.reaction_time) : std::string("-")) + ";";
    }
  }
  return line;
}

// The gaps behind an omission violation, hop by hop.
std::string Gateway::omission_line(const ChannelSpec& spec) const {
  std::string line =
      "channel " + spec.name + " violated its omission degree " + std::to_string(spec.omission_degree) + ":";
  for (const auto& stats : router_->snapshot()) {
    if (stats.name != spec.name) continue;
    for (const auto& seg : stats.segments) {
      if (seg.omission_excess == 0) continue;
      line += " hop " + seg.segment + ": " + std::to_string(seg.omission_excess) +
              " gaps in the end-to-end counter longer than that, " + std::to_string(seg.omitted) +
              " events missing in all;";
    }
  }
  return line;
}

std::size_t Gateway::violated_channels() const {
  return static_cast<std::size_t>(std::count_if(
      runtime_.begin(), runtime_.end(), [](const auto& t) { return t.second.state == RuntimeState::violated; }));
}

std::set<std::string> Gateway::violated_channel_names() const {
  std::set<std::string> names;
  for (const auto& [name, track] : runtime_) {
    if (track.state == RuntimeState::violated) names.insert(name);
  }
  return names;
}

std::vector<std::string> Gateway::take_thread_problems() {
  return router_ ? router_->take_thread_problems() : std::vector<std::string>{};
}

std::optional<std::size_t> Gateway::matched_peers(const std::string& segment, const std::string& channel) const {
  const auto slot = slots_.find(segment);
  const auto id = channel_ids_.find(channel);
  if (slot == slots_.end() || id == channel_ids_.end()) return std::nullopt;
  return slot->second.adapter->matched_peers(id->second.second);
}

std::optional<std::uint64_t> Gateway::incompatible_peers(const std::string& segment, const std::string& channel) const {
  const auto slot = slots_.find(segment);
  const auto id = channel_ids_.find(channel);
  if (slot == slots_.end() || id == channel_ids_.end()) return std::nullopt;
  return slot->second.adapter->incompatible_peers(id->second.second);
}

std::vector<PeerQosConflict> Gateway::peer_qos_conflicts(const std::string& segment, const std::string& channel) const {
  const auto slot = slots_.find(segment);
  const auto id = channel_ids_.find(channel);
  if (slot == slots_.end() || id == channel_ids_.end()) return {};
  return slot->second.adapter->peer_qos_conflicts(id->second.second);
}

bool Gateway::all_segments_up() const {
  return std::all_of(slots_.begin(), slots_.end(),
                     [](const auto& s) { return s.second.adapter->health().state == SegmentHealth::up; });
}

std::vector<SegmentInfo> Gateway::segments() const {
  const std::vector<SegmentLoad> loads = kb_->loads();
  const std::vector<std::size_t> hops = kb_->hop_counts();
  std::vector<SegmentInfo> out;
  for (const auto& spec : config_.segments) {
    const auto slot = slots_.find(spec.name);
    if (slot == slots_.end()) continue;
    SegmentInfo info{spec, slot->second.adapter->health(),       slot->second.adapter->statistics(), 0,
                     0,    router_->unrouted(slot->second.index)};
    for (std::size_t s = 0; s < loads.size() && s < hops.size(); ++s) {
      if (loads[s].name != spec.name) continue;
      info.utilization = loads[s].utilization;
      info.peers = loads[s].peers;
      info.channels = hops[s];
    }
    out.push_back(std::move(info));
  }
  return out;
}

Result<std::uint32_t> Gateway::open_tap(const std::string& channel) {
  const ChannelSpec* spec = kb_->find_bound(channel);
  const auto id = channel_ids_.find(channel);
  if (spec == nullptr || id == channel_ids_.end() || !router_) return Error{"no bound channel " + channel};
  const std::optional<std::uint32_t> tap = router_->taps().open(id->second.second, spec->payload);
  if (!tap) {
    return Error{"every tap is in use (" + std::to_string(TapBoard::kMaxTaps) + " at once): close an echo first"};
  }
  return *tap;
}

std::optional<TapRead> Gateway::read_tap(std::uint32_t tap) {
  if (!router_) return std::nullopt;
  return router_->taps().read(tap);
}

void Gateway::close_tap(std::uint32_t tap) {
  if (router_) router_->taps().close(tap);
}

}  // namespace cosmic

#include "cosmic/admission.hpp"

#include "cosmic/lcm_auth_layout.hpp"

#include "cosmic/dds_names.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>

#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"
#include "admission_judge.hpp"

namespace cosmic {
namespace {

using admission_detail::Judge;
using admission_detail::segment_named;

// A channel without a declared rate still occupies the bus (blocking), but reserves nothing.
constexpr Nanos kUnratedPeriod{3'600'000'000'000};
// Jitter standing in for an unbounded upstream latency: makes the analysis report unbounded.
constexpr Nanos kUnboundedJitter{100'000'000'000};
constexpr int kMaxJitterIterations = 32;
Nanos deadline_key(const ChannelSpec& channel) {
  if (channel.reaction_time) return *channel.reaction_time;
  if (channel.period) return *channel.period;
  return kUnratedPeriod;
}

std::size_t segment_index(std::span<const SegmentSpec> segments, const std::string& name) {
  return static_cast<std::size_t>(&segment_named(segments, name) - segments.data());
}

// The background frames that delay a CAN hop most, when its response time misses the channel's
// reaction time (what `cosmicctl check` names for a rejected channel); empty otherwise.
std::vector<BackgroundDelay> background_delaying(const SegmentSpec& segment, std::span<const CanStream> background,
                                                 const ChannelSpec& channel, const CanHopPlan& plan) {
  constexpr std::size_t kNamed = 3;
  if (segment.can.background.empty() || channel.cls == ChannelClass::nrt || !channel.reaction_time) return {};
  if (plan.response_time && *plan.response_time <= *channel.reaction_time) return {};
  const CanStream stream{arbitration_key(plan), plan.transmission, Nanos(0), plan.jitter};
  return dominant_background(segment.can, background, stream, plan.response_time, *channel.reaction_time, kNamed);
}

Nanos stream_period(const ChannelSpec& channel, const CanHopPlan& plan) {
  const Nanos period = channel.period.value_or(kUnratedPeriod);
  return std::max(Nanos(1), period / plan.frames_per_event);
}

// Frame layout of a channel on a CAN bus: what does not depend on the other channels.
// A native channel's frame is the event: never fragmented (admission's frame_fit refuses a payload
// larger than one frame), its identifier fixed.
CanHopPlan frame_plan(const SegmentSpec& segment, const ChannelSpec& channel) {
  const CanSegmentProperties& bus = segment.can;
  CanHopPlan plan;
  const std::optional<NativeCanFrame> native = channel.native_can(segment.name);
  const std::uint32_t capacity = max_frame_payload(bus);
  // A SecOC hop's frame carries the truncated freshness and MAC behind the data: never fragmented
  // (admission's frame_fit refuses what does not fit one frame).
  const SecocSpec* secoc = channel.secoc_on(segment.name);
  const std::uint64_t payload = channel.payload_on(segment.name) + (secoc ? secoc->overhead_bytes() : 0);
  const bool fits = payload <= capacity || native || secoc;
  plan.frames_per_event = fits ? 1 : fragments_needed(payload, capacity);
  const auto data_bytes = static_cast<std::uint32_t>(std::min<std::uint64_t>(payload, capacity));
  plan.frame_bytes = bus.fd ? fd_padded_length(data_bytes) : data_bytes;
  if (native) {
    plan.native = true;
    plan.extended = native->extended;
    plan.can_id = native->can_id;
  }
  plan.transmission =
      frame_time(bus, plan.frame_bytes, plan.extended ? CanIdFormat::extended29 : CanIdFormat::standard11);
  return plan;
}

double hop_load(const SegmentSpec& segment, const ChannelSpec& channel) {
  if (!channel.period) return 0.0;
  const double period_s = to_seconds(*channel.period);
  if (segment.type == SegmentType::can) {
    const CanHopPlan plan = frame_plan(segment, channel);
    return to_seconds(plan.transmission) * plan.frames_per_event / period_s;
  }
  const auto security = hop_security(segment, channel);
  const double bits =
      static_cast<double>(channel.payload_on(segment.name) + kIpOverheadBytes + (security ? security->bytes : 0)) * 8.0;
  return bits / period_s / static_cast<double>(segment.bandwidth.bits_per_second);
}

}  // namespace

std::optional<HopSecurity> hop_security(const SegmentSpec& segment, const ChannelSpec& channel) {
  if (segment.type == SegmentType::lcm && segment.lcm.auth)
    return HopSecurity{"HMAC-SHA256 trailer", static_cast<std::uint32_t>(kLcmAuthTrailerSize), segment.lcm.auth->cost};
  if (segment.type == SegmentType::dds && segment.dds.security) {
    return HopSecurity{"DDS Security AES-GCM-GMAC", static_cast<std::uint32_t>(kDdsSecurityMaxOverheadBytes),
                       segment.dds.security->cost};
  }
  const SecocSpec* secoc = segment.type == SegmentType::can ? channel.secoc_on(segment.name) : nullptr;
  if (secoc == nullptr) return std::nullopt;
  return HopSecurity{"SecOC AES-128-CMAC " + std::to_string(secoc->mac_bits) + "-bit MAC, " +
                         std::to_string(secoc->freshness_bits) + "-bit freshness",
                     secoc->overhead_bytes(), secoc->cost};
}

Nanos can_hop_security_cost(const SegmentSpec& segment, const ChannelSpec& channel) {
  const SecocSpec* secoc = segment.type == SegmentType::can ? channel.secoc_on(segment.name) : nullptr;
  return secoc && secoc->cost ? *secoc->cost : Nanos(0);
}

Nanos ip_hop_latency(const SegmentSpec& segment) {
  if (segment.type == SegmentType::dds && segment.dds.security && segment.dds.security->cost)
    return segment.latency_bound + *segment.dds.security->cost;
  const bool costed = segment.type == SegmentType::lcm && segment.lcm.auth && segment.lcm.auth->cost;
  return segment.latency_bound + (costed ? *segment.lcm.auth->cost : Nanos(0));
}

const char* to_string(Verdict value) {
  switch (value) {
    case Verdict::bound:
      return "bound";
    case Verdict::degraded:
      return "degraded";
    case Verdict::rejected:
      return "rejected";
    case Verdict::failed:
      return "failed";
  }
  return "?";
}

const char* to_string(HopRole value) { return value == HopRole::publisher ? "publisher" : "subscriber"; }

bool AdmissionReport::any_rejected() const {
  return std::any_of(channels.begin(), channels.end(), [](const auto& c) { return c.verdict == Verdict::rejected; });
}

ChannelReport rejected_report(const ChannelSpec& channel, std::string reason) {
  ChannelReport report;
  report.name = channel.name;
  report.cls = channel.cls;
  report.verdict = Verdict::rejected;
  report.reasons.push_back(std::move(reason));
  return report;
}

const ChannelReport* AdmissionReport::find(const std::string& name) const {
  const auto it = std::find_if(channels.begin(), channels.end(), [&](const auto& c) { return c.name == name; });
  return it == channels.end() ? nullptr : &*it;
}

Verdict consequence_of(const std::string& check, ChannelClass cls) {
  if (cls == ChannelClass::hrt || check == "frame_fit" || check == "representation" || check == "authentication" ||
      check == "replay_events" || check == "fmu_rate")
    return Verdict::rejected;
  return Verdict::degraded;
}

Evaluation evaluate(const GatewaySpec& gateway, std::span<const SegmentSpec> segments,
                    std::span<const ChannelSpec> channels, const EtagMap& etags) {
  const AdmissionSet set =
      AdmissionSet::whole(gateway, std::vector<SegmentSpec>(segments.begin(), segments.end()), channels, etags);
  return Evaluation{set.reports(), set.loads()};
}

AdmissionSet::AdmissionSet(GatewaySpec gateway, std::vector<SegmentSpec> segments)
    : gateway_(std::move(gateway)), segment_specs_(std::move(segments)), segments_(segment_specs_.size()) {
  // What a network carries before any channel is bound: a CAN bus its background frames (other
  // gateways' frames among them), an IP network what other gateways reserve there.
  for (std::size_t s = 0; s < segments_.size(); ++s) init_segment(s);
}

void AdmissionSet::init_segment(std::size_t s) {
  if (segment_specs_[s].type == SegmentType::can) {
    segments_[s].background = background_streams(segment_specs_[s].can);
    segments_[s].background_load = utilization(segments_[s].background);
  } else {
    segments_[s].background_load = segment_specs_[s].peer_load;
  }
  segments_[s].load = segments_[s].background_load;
}

AdmissionSet AdmissionSet::whole(GatewaySpec gateway, std::vector<SegmentSpec> segments,
                                 std::span<const ChannelSpec> channels, const EtagMap& etags) {
  AdmissionSet set(std::move(gateway), std::move(segments));
  for (const ChannelSpec& channel : channels) {
    const auto etag = etags.find(channel.name);
    ChannelData data = set.place(channel, etag == etags.end() ? 0 : etag->second);
    for (const HopPlace& p : data.places)
      set.segments_[p.segment].load += hop_load(set.segment_specs_[p.segment], channel);
    set.append(channel, std::move(data));
  }
  set.apply(set.analyse_can(nullptr, true));
  return set;
}

AdmissionSet::ChannelData AdmissionSet::place(const ChannelSpec& channel, std::uint16_t etag) const {
  ChannelData data{etag, {}};
  auto add = [&](const std::string& name, HopRole role) {
    const std::size_t s = segment_index(segment_specs_, name);
    const auto earlier =
        std::count_if(data.places.begin(), data.places.end(), [&](const auto& p) { return p.segment == s; });
    data.places.push_back(HopPlace{s, segments_[s].hops.size() + static_cast<std::size_t>(earlier), role});
  };
  for (const auto& p : channel.publishers) add(p, HopRole::publisher);
  for (const auto& s : channel.subscribers) add(s, HopRole::subscriber);
  return data;
}

void AdmissionSet::append(ChannelSpec spec, ChannelData data) {
  const std::size_t index = specs_.size();
  for (std::size_t h = 0; h < data.places.size(); ++h)
    segments_[data.places[h].segment].hops.push_back(HopRef{index, h});
  index_[spec.name] = index;
  specs_.push_back(std::move(spec));
  data_.push_back(std::move(data));
}

AdmissionSet::Member AdmissionSet::member(std::size_t segment, std::size_t position, const Trial* newcomer) const {
  const auto& hops = segments_[segment].hops;
  if (position < hops.size()) {
    const HopRef& ref = hops[position];
    return Member{&specs_[ref.channel], &data_[ref.channel], data_[ref.channel].places[ref.hop].role};
  }
  for (const HopPlace& p : newcomer->data.places) {
    if (p.segment == segment && p.position == position) return Member{&newcomer->spec, &newcomer->data, p.role};
  }
  return Member{nullptr, nullptr, HopRole::publisher};  // unreachable: positions come from place()
}

// Priorities (band, then deadline-monotonic), identifiers and frame times of one CAN bus, in the
// order of its hop list (the newcomer's hops last). Each identifier is the one on the wire in the
// bus's profile (CanHopPlan): on a FAMOUSO bus the gateway's frames carry the planned priority in
// 7 bits (famouso_priority) and the fragment flag, while the nodes publish at their own fixed
// priority, so only subscriber hops take a level of the bands there.
std::vector<CanHopPlan> AdmissionSet::plan_bus(std::size_t segment, const Trial* newcomer) const {
  std::vector<Member> members;
  for (std::size_t pos = 0; pos < segments_[segment].hops.size(); ++pos)
    members.push_back(member(segment, pos, nullptr));
  if (newcomer) {
    for (const HopPlace& p : newcomer->data.places) {
      if (p.segment == segment) members.push_back(Member{&newcomer->spec, &newcomer->data, p.role});
    }
  }
  const CanSegmentProperties& bus = segment_specs_[segment].can;
  const bool famouso = bus.profile == CanProfile::famouso;
  std::vector<CanHopPlan> plans(members.size());
  std::vector<std::size_t> ordered;
  for (std::size_t i = 0; i < members.size(); ++i) {
    CanHopPlan& plan = plans[i];
    plan = frame_plan(segment_specs_[segment], *members[i].spec);
    plan.profile = bus.profile;
    if (plan.native) continue;  // its identifier is the devices' own
    plan.etag = members[i].data->etag;
    if (famouso && members[i].role == HopRole::publisher) {
      plan.priority = kFamousoProtocolPriority;
      plan.can_id = encode_famouso_id(
          FamousoIdentifier{plan.priority, plan.frames_per_event > 1, kFamousoLastAssignedNode, plan.etag});
    } else {
      ordered.push_back(i);
    }
  }
  std::sort(ordered.begin(), ordered.end(), [&](std::size_t a, std::size_t b) {
    const ChannelSpec& ca = *members[a].spec;
    const ChannelSpec& cb = *members[b].spec;
    return std::tuple(static_cast<int>(ca.cls), deadline_key(ca), ca.subject) <
           std::tuple(static_cast<int>(cb.cls), deadline_key(cb), cb.subject);
  });
  std::array<std::size_t, 3> count{};
  for (const std::size_t i : ordered) ++count[static_cast<std::size_t>(members[i].spec->cls)];
  std::size_t first_of_class = 0;
  for (std::size_t k = 0; k < ordered.size(); ++k) {
    const ChannelSpec& spec = *members[ordered[k]].spec;
    if (k > 0 && members[ordered[k - 1]].spec->cls != spec.cls) first_of_class = k;
    CanHopPlan& plan = plans[ordered[k]];
    const std::uint8_t planned = band_priority(spec.cls, k - first_of_class, count[static_cast<std::size_t>(spec.cls)]);
    if (famouso) {
      plan.priority = famouso_priority(planned);
      plan.can_id = encode_famouso_id(
          FamousoIdentifier{plan.priority, plan.frames_per_event > 1, gateway_.can_node_id, plan.etag});
    } else {
      plan.priority = planned;
      plan.can_id = encode_can_id(CanIdentifier{plan.priority, gateway_.can_node_id, plan.etag});
    }
  }
  return plans;
}

// Subscriber-side CAN streams are released by the gateway up to (upstream latency + residence)
// after the event occurred: that is their jitter. True when a jitter changed.
bool AdmissionSet::update_jitters(CanSide& side, const Trial* newcomer) const {
  bool changed = false;
  for (std::size_t s = 0; s < side.plans.size(); ++s) {
    for (std::size_t pos = 0; pos < side.plans[s].size(); ++pos) {
      const Member m = member(s, pos, newcomer);
      if (m.role != HopRole::subscriber) continue;
      std::optional<Nanos> upstream = Nanos(0);
      for (const HopPlace& p : m.data->places) {
        if (p.role != HopRole::publisher) continue;
        const SegmentSpec& publisher = segment_specs_[p.segment];
        std::optional<Nanos> latency = std::optional<Nanos>(ip_hop_latency(publisher));
        if (publisher.type == SegmentType::can) {
          latency = side.plans[p.segment][p.position].response_time;
          if (latency) *latency += can_hop_security_cost(publisher, *m.spec);
        }
        upstream = upstream && latency ? std::optional<Nanos>(std::max(*upstream, *latency)) : std::nullopt;
      }
      // SecOC protects the frame before it is released: its cost is part of the release jitter.
      const Nanos protect = can_hop_security_cost(segment_specs_[s], *m.spec);
      const Nanos jitter =
          upstream ? std::min(kUnboundedJitter, *upstream + gateway_.residence_bound + protect) : kUnboundedJitter;
      CanHopPlan& plan = side.plans[s][pos];
      if (plan.jitter == jitter) continue;
      plan.jitter = jitter;
      changed = true;
    }
  }
  return changed;
}

// Response times of every CAN bus with the holistic jitter iteration (from zero jitter to the
// fixed point, as a whole-set analysis does). Buses the newcomer joins (all with replan_all) get
// fresh priorities; the others keep theirs, which are fresh unless a removal pinned them. Each bus run reuses the
// committed run of the same iteration for the streams whose higher-priority prefix did not change.
AdmissionSet::CanSide AdmissionSet::analyse_can(const Trial* newcomer, bool replan_all) const {
  CanSide side;
  side.replanned.assign(segments_.size(), false);
  side.plans.resize(segments_.size());
  side.runs.resize(segments_.size());
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    if (segment_specs_[s].type != SegmentType::can) continue;
    side.replanned[s] =
        replan_all || (newcomer && std::any_of(newcomer->data.places.begin(), newcomer->data.places.end(),
                                               [&](const HopPlace& p) { return p.segment == s; }));
    side.plans[s] = side.replanned[s] ? plan_bus(s, newcomer) : segments_[s].plans;
    for (CanHopPlan& plan : side.plans[s]) plan.jitter = Nanos(0);
    side.runs[s].reserve(kMaxJitterIterations);
  }
  for (int iteration = 0; iteration < kMaxJitterIterations; ++iteration) {
    const auto it = static_cast<std::size_t>(iteration);
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      if (side.plans[s].empty()) continue;
      std::vector<CanStream> streams;
      const std::vector<CanStream>& background = segments_[s].background;
      streams.reserve(side.plans[s].size() + background.size());
      for (std::size_t pos = 0; pos < side.plans[s].size(); ++pos) {
        const CanHopPlan& plan = side.plans[s][pos];
        streams.push_back(CanStream{arbitration_key(plan), plan.transmission,
                                    stream_period(*member(s, pos, newcomer).spec, plan), plan.jitter});
      }
      // Other devices' frames after ours: the results read below are the first plans.size().
      streams.insert(streams.end(), background.begin(), background.end());
      const auto& committed = segments_[s].runs;
      const CanBusAnalysis* memo = it < committed.size() ? &committed[it]
                                   : it > 0              ? &side.runs[s][it - 1]
                                   : committed.empty()   ? nullptr
                                                         : &committed.back();
      side.runs[s].emplace_back(streams, bus_timing(segment_specs_[s].can), memo);
      const auto& results = side.runs[s].back().results();
      for (std::size_t pos = 0; pos < side.plans[s].size(); ++pos) side.plans[s][pos].response_time = results[pos];
    }
    if (!update_jitters(side, newcomer)) return side;
  }
  side.diverged = true;  // the jitters keep growing: the subscriber-side CAN hops are unbounded
  return side;
}

void AdmissionSet::apply(CanSide side) {
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    if (segment_specs_[s].type != SegmentType::can) continue;
    segments_[s].plans = std::move(side.plans[s]);
    segments_[s].runs = std::move(side.runs[s]);
    if (side.replanned[s]) segments_[s].pinned = false;
  }
  diverged_ = side.diverged;
}

ChannelReport AdmissionSet::report_of(const ChannelSpec& spec, const ChannelData& data, const Trial* change) const {
  const CanSide* can = change && change->can ? &*change->can : nullptr;
  const bool diverged = can ? can->diverged : diverged_;
  ChannelReport report;
  report.name = spec.name;
  report.cls = spec.cls;
  for (const HopPlace& p : data.places) {
    const SegmentSpec& segment = segment_specs_[p.segment];
    HopReport h{segment.name, p.role, std::nullopt, std::nullopt, std::nullopt, {}, {}, {}};
    if (segment.type == SegmentType::can) {
      CanHopPlan plan = can ? can->plans[p.segment][p.position] : segments_[p.segment].plans[p.position];
      if (diverged && p.role == HopRole::subscriber) plan.response_time = std::nullopt;
      // SecOC's cryptography: checking a received frame after it; protecting one is in the release
      // jitter, and so in the response time, of a subscriber hop.
      h.latency = plan.response_time;
      if (h.latency && p.role == HopRole::publisher) *h.latency += can_hop_security_cost(segment, spec);
      h.background = background_delaying(segment, segments_[p.segment].background, spec, plan);
      h.can = plan;
    } else {
      h.latency = ip_hop_latency(segment);
      if (segment.type == SegmentType::dds) h.dds = dds_topic_of(spec, segment.name);
    }
    report.hops.push_back(std::move(h));
  }
  std::vector<double> loads(segments_.size());
  for (std::size_t s = 0; s < segments_.size(); ++s) loads[s] = segments_[s].load;
  if (change) {
    for (const auto& [s, load] : change->loads) loads[s] = load;
  }
  Judge(gateway_, segment_specs_, loads).judge(spec, report);
  return report;
}

AdmissionSet::Trial AdmissionSet::trial(const ChannelSpec& channel, std::uint16_t etag) const {
  Trial t;
  t.spec = channel;
  t.data = place(channel, etag);
  bool touches_can = false;
  for (const HopPlace& p : t.data.places) {
    touches_can = touches_can || segment_specs_[p.segment].type == SegmentType::can;
    auto load = std::find_if(t.loads.begin(), t.loads.end(), [&](const auto& l) { return l.first == p.segment; });
    if (load == t.loads.end()) load = t.loads.insert(t.loads.end(), {p.segment, segments_[p.segment].load});
    load->second += hop_load(segment_specs_[p.segment], channel);
  }
  if (touches_can) {
    t.can = analyse_can(&t, false);
    t.broken_frames = frames_broken_by(*t.can);
  }
  t.report = report_of(t.spec, t.data, &t);
  for (const std::size_t c : affected_by(t)) {
    if (specs_[c].cls != ChannelClass::hrt) continue;
    ChannelReport existing = report_of(specs_[c], data_[c], &t);
    if (existing.verdict == Verdict::rejected) t.broken_hrt.push_back(std::move(existing));
  }
  return t;
}

// Background frames with a deadline (on any bus: a newcomer elsewhere can change the release jitter
// of a channel's downstream CAN hop) that met it in the committed analysis and miss it in `side`'s.
// A frame already late before is not the newcomer's doing.
std::vector<AdmissionSet::Trial::BrokenFrame> AdmissionSet::frames_broken_by(const CanSide& side) const {
  std::vector<Trial::BrokenFrame> out;
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const std::vector<CanBackgroundFrame>& frames = segment_specs_[s].can.background;
    const bool any = std::any_of(frames.begin(), frames.end(), [](const auto& f) { return f.deadline.has_value(); });
    if (!any || side.runs[s].empty()) continue;
    const auto& after = side.runs[s].back().results();
    // Before: the committed analysis, or the background alone on a bus without channels yet.
    std::vector<std::optional<Nanos>> alone;
    const std::vector<std::optional<Nanos>>* before = nullptr;
    std::size_t before_first = segments_[s].plans.size();
    if (!segments_[s].runs.empty()) {
      before = &segments_[s].runs.back().results();
    } else {
      alone = response_times(segments_[s].background, bus_timing(segment_specs_[s].can));
      before = &alone;
      before_first = 0;
    }
    const std::size_t after_first = side.plans[s].size();
    for (std::size_t k = 0; k < frames.size(); ++k) {
      if (!frames[k].deadline) continue;
      const std::optional<Nanos>& r = after.at(after_first + k);
      if (r && *r <= *frames[k].deadline) continue;
      const std::optional<Nanos>& b = before->at(before_first + k);
      if (!b || *b > *frames[k].deadline) continue;
      out.push_back({frames[k].name, frames[k].origin, r, *frames[k].deadline});
    }
  }
  return out;
}

// Bound channels whose report the trial can change: those on a segment it pushes over its
// utilization limit and those with a CAN hop whose plan or bound it changes. Bind order.
std::vector<std::size_t> AdmissionSet::affected_by(const Trial& t) const {
  std::vector<std::size_t> out;
  for (const auto& [s, load] : t.loads) {
    if (load <= segment_specs_[s].max_utilization + 1e-12) continue;
    for (const HopRef& ref : segments_[s].hops) out.push_back(ref.channel);
  }
  if (t.can) {
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      for (std::size_t pos = 0; pos < segments_[s].plans.size(); ++pos) {
        const CanHopPlan& before = segments_[s].plans[pos];
        const CanHopPlan& after = t.can->plans[s][pos];
        const HopRef& ref = segments_[s].hops[pos];
        const bool bound_changed =
            t.can->diverged != diverged_ && data_[ref.channel].places[ref.hop].role == HopRole::subscriber;
        if (bound_changed || before.can_id != after.can_id || before.jitter != after.jitter ||
            before.response_time != after.response_time) {
          out.push_back(ref.channel);
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void AdmissionSet::commit(Trial t) {
  for (const auto& [s, load] : t.loads) segments_[s].load = load;
  if (t.can) apply(std::move(*t.can));
  append(std::move(t.spec), std::move(t.data));
}

bool AdmissionSet::remove(const std::string& name) {
  const auto found = index_.find(name);
  if (found == index_.end()) return false;
  const std::size_t gone = found->second;
  std::vector<std::size_t> touched;
  for (const HopPlace& p : data_[gone].places) {
    if (std::find(touched.begin(), touched.end(), p.segment) == touched.end()) touched.push_back(p.segment);
  }
  for (const std::size_t s : touched) {
    Segment& seg = segments_[s];
    std::vector<HopRef> hops;
    std::vector<CanHopPlan> plans;
    for (std::size_t pos = 0; pos < seg.hops.size(); ++pos) {
      if (seg.hops[pos].channel == gone) continue;
      hops.push_back(seg.hops[pos]);
      if (!seg.plans.empty()) plans.push_back(seg.plans[pos]);
    }
    seg.hops = std::move(hops);
    seg.plans = std::move(plans);
    seg.pinned = segment_specs_[s].type == SegmentType::can;
  }
  specs_.erase(specs_.begin() + static_cast<std::ptrdiff_t>(gone));
  data_.erase(data_.begin() + static_cast<std::ptrdiff_t>(gone));
  index_.erase(found);
  for (auto& [n, i] : index_) {
    if (i > gone) --i;
  }
  for (Segment& seg : segments_) {
    for (HopRef& ref : seg.hops) {
      if (ref.channel > gone) --ref.channel;
    }
  }
  for (const std::size_t s : touched) {
    segments_[s].load = segments_[s].background_load;
    for (std::size_t pos = 0; pos < segments_[s].hops.size(); ++pos) {
      const HopRef& ref = segments_[s].hops[pos];
      data_[ref.channel].places[ref.hop].position = pos;
      segments_[s].load += hop_load(segment_specs_[s], specs_[ref.channel]);
    }
  }
  const bool can = std::any_of(touched.begin(), touched.end(),
                               [&](std::size_t s) { return segment_specs_[s].type == SegmentType::can; });
  if (can) apply(analyse_can(nullptr, false));
  return true;
}

const ChannelSpec* AdmissionSet::find(const std::string& name) const {
  const auto it = index_.find(name);
  return it == index_.end() ? nullptr : &specs_[it->second];
}

std::vector<ChannelReport> AdmissionSet::reports() const {
  std::vector<ChannelReport> out;
  out.reserve(specs_.size());
  for (std::size_t c = 0; c < specs_.size(); ++c) out.push_back(report_of(specs_[c], data_[c], nullptr));
  return out;
}

std::vector<std::size_t> AdmissionSet::hop_counts() const {
  std::vector<std::size_t> out(segment_specs_.size(), 0);
  for (const ChannelData& channel : data_) {
    for (const HopPlace& p : channel.places) ++out.at(p.segment);
  }
  return out;
}

std::vector<SegmentLoad> AdmissionSet::loads() const {
  std::vector<SegmentLoad> out;
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const SegmentSpec& spec = segment_specs_[s];
    const bool can = spec.type == SegmentType::can;
    out.push_back(SegmentLoad{spec.name, spec.type, segments_[s].load, spec.max_utilization,
                              can ? segments_[s].background_load : 0.0, can ? spec.can.background.size() : 0,
                              spec.peer_load});
  }
  return out;
}

}  // namespace cosmic

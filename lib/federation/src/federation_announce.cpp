// What a gateway announces about itself, taken from its knowledge base.
#include <algorithm>

#include "cosmic/federation.hpp"
#include "cosmic/knowledge_base.hpp"

namespace cosmic {
namespace {

// How much longer the hop's response time may grow with the HRT channel still admitted: the room
// under its own check (R <= reaction_time), and its share of the room under the end-to-end ones,
// split evenly between the channel's `can_hops` (each may be on a bus other gateways share, and
// their binds there must not spend the same room twice). Nullopt: none to give.
std::optional<Nanos> slack_of(const ChannelSpec& spec, const HopReport& hop, const EndToEnd& e2e,
                              std::size_t can_hops) {
  if (spec.cls != ChannelClass::hrt || !spec.reaction_time || !hop.latency || !e2e.latency) return std::nullopt;
  Nanos end_to_end = *spec.reaction_time - *e2e.latency;
  if (spec.temp_validity) end_to_end = std::min(end_to_end, *spec.temp_validity - *e2e.latency - Nanos(1));
  const Nanos slack = std::min(*spec.reaction_time - *hop.latency,
                               end_to_end / static_cast<std::int64_t>(std::max<std::size_t>(1, can_hops)));
  if (slack < Nanos(0)) return std::nullopt;
  return slack;
}

// The frames a bound channel's CAN hop puts on the bus: one stream per hop, an event of n
// fragments counted as n frames per period (the same load; the spacing is the sender's).
std::optional<AnnouncedFrame> frame_of(const ChannelSpec& spec, const HopReport& hop, const EndToEnd& e2e,
                                       std::size_t can_hops) {
  if (!hop.can || !spec.period || spec.period->count() <= 0) return std::nullopt;
  const auto frames = std::max<std::uint32_t>(1, hop.can->frames_per_event);
  AnnouncedFrame f;
  f.channel = spec.name;
  f.can_id = hop.can->can_id;
  f.extended = hop.can->extended;
  f.length = hop.can->frame_bytes;
  f.period = std::max(Nanos(1000), *spec.period / frames);
  f.jitter = hop.can->jitter;
  if (const auto slack = slack_of(spec, hop, e2e, can_hops)) f.deadline = *hop.latency + *slack;
  return f;
}

AnnouncedChannel channel_of(const ChannelReport& report, const ChannelSpec& spec) {
  AnnouncedChannel c;
  c.name = report.name;
  c.subject = spec.subject;
  c.cls = report.cls;
  c.verdict = report.verdict == Verdict::rejected ? Verdict::failed : report.verdict;
  for (const HopReport& hop : report.hops) c.hops.push_back(AnnouncedHop{hop.segment, hop.role, hop.latency});
  c.end_to_end = report.end_to_end.latency;
  c.period = spec.period;
  c.reaction_time = spec.reaction_time;
  c.temp_validity = spec.temp_validity;
  c.payload = spec.payload;
  c.upstream = report.upstream;
  c.upstream_age = report.end_to_end.upstream;
  // What no peer would decode: an over-long path or an age beyond the codec's bounds is announced
  // as unbounded (the conservative reading), not refused with the whole announcement.
  auto bounded = [](std::optional<Nanos>& value) {
    if (value && (*value < Nanos(0) || *value > kMaxAnnouncedDuration)) value.reset();
  };
  if (c.upstream.size() > kMaxAnnouncedHops) {
    c.upstream.clear();
    c.upstream_age.reset();
    c.end_to_end.reset();
  }
  bounded(c.upstream_age);
  bounded(c.end_to_end);
  return c;
}

}  // namespace

Announcement announcement_of(const GatewayIdentity& self, const KnowledgeBase& kb, std::uint64_t revision,
                             const std::set<std::string>& violated) {
  Announcement a;
  a.gateway = self.id;
  a.name = self.name;
  a.revision = revision;
  a.residence = kb.gateway().residence_bound;
  const AdmissionReport report = kb.report();
  for (std::size_t i = 0; i < kb.segments().size() && i < report.segments.size(); ++i) {
    const SegmentSpec& spec = kb.segments()[i].spec;
    const SegmentLoad& load = report.segments[i];
    AnnouncedSegment s;
    s.name = spec.name;
    s.type = spec.type;
    s.network = network_identity(spec);
    s.max_utilization = spec.max_utilization;
    const double others = spec.type == SegmentType::can ? load.background : load.peers;
    s.load = std::clamp(load.utilization - others, 0.0, 1.0);
    if (spec.type != SegmentType::can) s.reserved_bps = s.load * static_cast<double>(spec.bandwidth.bits_per_second);
    a.segments.push_back(std::move(s));
  }
  for (const ChannelReport& channel : report.channels) {
    const ChannelSpec* spec = kb.find_bound(channel.name);
    if (!spec) continue;
    // Past the bound a peer accepts, channels are left out of the list; their load and frames stay.
    if (a.channels.size() < kMaxAnnouncedChannels) {
      a.channels.push_back(channel_of(channel, *spec));
      a.channels.back().violated = violated.count(channel.name) > 0;
    }
    const auto can_hops = static_cast<std::size_t>(
        std::count_if(channel.hops.begin(), channel.hops.end(), [](const HopReport& h) { return h.can.has_value(); }));
    for (const HopReport& hop : channel.hops) {
      const auto frame = frame_of(*spec, hop, channel.end_to_end, can_hops);
      if (!frame) continue;
      for (AnnouncedSegment& s : a.segments) {
        if (s.name == hop.segment && s.frames.size() < kMaxAnnouncedFrames) s.frames.push_back(*frame);
      }
    }
  }
  return a;
}

}  // namespace cosmic

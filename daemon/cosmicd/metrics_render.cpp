#include "metrics_render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cosmic/can_background.hpp"
#include "cosmic/router_stats.hpp"

namespace cosmicd {
namespace {

using cosmic::ChannelReport;
using cosmic::HopReport;
using cosmic::SegmentCountersSnapshot;

// Divided, not multiplied by 1e-9: 500000 ns reads back as exactly 0.0005.
double seconds(cosmic::Nanos value) { return static_cast<double>(value.count()) / 1e9; }
double seconds_or_inf(const std::optional<cosmic::Nanos>& value) {
  return value ? seconds(*value) : std::numeric_limits<double>::infinity();
}

// One channel on one segment, with the router's counters for it when it has any yet.
struct HopView {
  const ChannelReport* channel = nullptr;
  const HopReport* hop = nullptr;
  const SegmentCountersSnapshot* counters = nullptr;
  const cosmic::ChannelStatsSnapshot* stats = nullptr;
};

const cosmic::ChannelStatsSnapshot* find_stats(const MetricsSnapshot& snapshot, const std::string& name) {
  const auto it =
      std::find_if(snapshot.stats.begin(), snapshot.stats.end(), [&](const auto& s) { return s.name == name; });
  return it == snapshot.stats.end() ? nullptr : &*it;
}

std::vector<HopView> hop_views(const MetricsSnapshot& snapshot) {
  std::vector<HopView> views;
  for (const auto& channel : snapshot.channels) {
    const auto* stats = find_stats(snapshot, channel.name);
    for (const auto& hop : channel.hops) {
      HopView view{&channel, &hop, nullptr, stats};
      if (stats) {
        for (const auto& counters : stats->segments) {
          if (counters.segment == hop.segment) view.counters = &counters;
        }
      }
      views.push_back(view);
    }
  }
  return views;
}

Labels channel_labels(const ChannelReport& channel) {
  return {{"channel", channel.name}, {"class", cosmic::to_string(channel.cls)}};
}

Labels hop_labels(const HopView& view) {
  Labels labels = channel_labels(*view.channel);
  labels.emplace_back("segment", view.hop->segment);
  labels.emplace_back("role", cosmic::to_string(view.hop->role));
  return labels;
}

Labels segment_labels(const cosmic::SegmentInfo& segment) {
  return {{"segment", segment.spec.name}, {"type", cosmic::to_string(segment.spec.type)}};
}

void render_gateway(Exposition& out, const MetricsSnapshot& s) {
  out.family("cosmic_gateway_info", MetricType::gauge, "Constant 1, labelled with the gateway's name and id.");
  out.sample({{"gateway", s.gateway_name}, {"id", s.gateway_id}}, 1.0);
  out.family("cosmic_gateway_uptime_seconds", MetricType::gauge, "Time since cosmicd started.");
  out.sample({}, s.uptime_seconds);
  out.family("cosmic_gateway_residence_bound_seconds", MetricType::gauge,
             "Configured worst-case time an event spends inside the gateway (gateway.residence_bound).");
  out.sample({}, seconds(s.residence_bound));
  out.family("cosmic_router_queued_events", MetricType::gauge, "Events waiting in the router's egress queues.");
  out.sample({}, static_cast<std::uint64_t>(s.router_queued));
  out.family("cosmic_router_handled_events", MetricType::counter, "Events the router has sent or dropped since start.");
  out.sample({}, s.router_handled);
}

void render_segment_health(Exposition& out, const MetricsSnapshot& s) {
  out.family("cosmic_segment_up", MetricType::gauge, "1 when the segment is healthy, 0 when degraded or down.");
  for (const auto& seg : s.segments)
    out.sample(segment_labels(seg), seg.health.state == cosmic::SegmentHealth::up ? 1.0 : 0.0);
  out.family("cosmic_segment_health", MetricType::gauge,
             "1 for the segment's current health state (up, degraded, down), 0 for the others.");
  for (const auto& seg : s.segments) {
    for (const auto state : {cosmic::SegmentHealth::up, cosmic::SegmentHealth::degraded, cosmic::SegmentHealth::down}) {
      Labels labels = segment_labels(seg);
      labels.emplace_back("state", cosmic::to_string(state));
      out.sample(labels, seg.health.state == state ? 1.0 : 0.0);
    }
  }
  out.family("cosmic_segment_reserved_utilization_ratio", MetricType::gauge,
             "Share of the segment's bandwidth reserved by admission.");
  for (const auto& seg : s.segments) out.sample(segment_labels(seg), seg.utilization);
  out.family("cosmic_segment_max_utilization_ratio", MetricType::gauge,
             "Share of the bandwidth the gateway may reserve (max_utilization).");
  for (const auto& seg : s.segments) out.sample(segment_labels(seg), seg.spec.max_utilization);
  out.family("cosmic_segment_channels", MetricType::gauge, "Channels bound on the segment.");
  for (const auto& seg : s.segments) out.sample(segment_labels(seg), static_cast<std::uint64_t>(seg.channels));
}

void render_segment_counters(Exposition& out, const MetricsSnapshot& s) {
  struct Counter {
    const char* name;
    const char* help;
    std::uint64_t cosmic::SegmentInfo::*field = nullptr;
    std::uint64_t cosmic::AdapterStatistics::*adapter = nullptr;
  };
  const Counter counters[] = {
      {"cosmic_segment_unrouted_events", "Events received on the segment for no channel bound there.",
       &cosmic::SegmentInfo::unrouted},
      {"cosmic_segment_received_messages", "Messages or frames the adapter read from the network.", nullptr,
       &cosmic::AdapterStatistics::received},
      {"cosmic_segment_sent_messages", "Messages or frames the adapter wrote to the network.", nullptr,
       &cosmic::AdapterStatistics::sent},
      {"cosmic_segment_receive_errors", "Malformed or unreadable input on the segment.", nullptr,
       &cosmic::AdapterStatistics::receive_errors},
      {"cosmic_segment_send_errors", "Writes the network refused.", nullptr, &cosmic::AdapterStatistics::send_errors},
      {"cosmic_segment_overflow_drops",
       "Messages lost before the adapter could read them (kernel receive queue overflow).", nullptr,
       &cosmic::AdapterStatistics::overflow_drops},
  };
  for (const auto& counter : counters) {
    out.family(counter.name, MetricType::counter, counter.help);
    for (const auto& seg : s.segments)
      out.sample(segment_labels(seg), counter.field ? seg.*counter.field : seg.adapter.*counter.adapter);
  }
  out.family("cosmic_segment_send_backlog_messages", MetricType::gauge,
             "Messages waiting in the adapter's own send queue.");
  for (const auto& seg : s.segments) out.sample(segment_labels(seg), seg.adapter.backlog);
  out.family("cosmic_segment_unexplained_frames", MetricType::counter,
             "CAN frames of an identifier no bound channel, binding protocol or background declaration explains.");
  for (const auto& seg : s.segments) {
    for (const auto& f : seg.adapter.unexplained) {
      Labels labels = segment_labels(seg);
      labels.emplace_back("can_id", cosmic::can_id_text(f.can_id, f.extended));
      out.sample(labels, f.frames);
    }
  }
  out.family("cosmic_segment_own_datagrams_dropped", MetricType::counter,
             "LCM datagrams the gateway sent whose looped-back copy its receive filter dropped (own_datagrams: drop); "
             "each is one in the host's UDP InErrors.");
  for (const auto& seg : s.segments)
    if (const auto own = seg.adapter.transport_counter("own_datagrams_dropped")) out.sample(segment_labels(seg), *own);
  out.family("cosmic_segment_unauthenticated", MetricType::counter,
             "Messages of an authenticated segment (LCM auth) or frames of a CAN segment's SecOC hops dropped for "
             "want of a valid authentication tag.");
  for (const auto& seg : s.segments) {
    if (seg.spec.type == cosmic::SegmentType::dds) continue;  // participants, counted below
    if (const auto n = seg.adapter.transport_counter("unauthenticated")) out.sample(segment_labels(seg), *n);
  }
  out.family("cosmic_segment_unauthenticated_participants", MetricType::counter,
             "Remote participants a secure DDS segment (security) refused authentication, each counted once.");
  for (const auto& seg : s.segments) {
    if (seg.spec.type != cosmic::SegmentType::dds) continue;
    if (const auto n = seg.adapter.transport_counter("unauthenticated")) out.sample(segment_labels(seg), *n);
  }
  out.family("cosmic_segment_replayed", MetricType::counter,
             "Messages of an authenticated segment (LCM auth) with a valid tag dropped as sent before, or signed "
             "outside the freshness window; frames of SecOC hops authentic once and sent again.");
  for (const auto& seg : s.segments)
    if (const auto n = seg.adapter.transport_counter("replayed")) out.sample(segment_labels(seg), *n);
}

void render_channel_state(Exposition& out, const MetricsSnapshot& s) {
  out.family("cosmic_channel_verdict", MetricType::gauge,
             "1 for the channel's verdict (bound, degraded, rejected; failed: admitted but refused by a transport), 0 "
             "for the others.");
  for (const auto& c : s.channels) {
    for (const auto verdict :
         {cosmic::Verdict::bound, cosmic::Verdict::degraded, cosmic::Verdict::rejected, cosmic::Verdict::failed}) {
      Labels labels = channel_labels(c);
      labels.emplace_back("verdict", cosmic::to_string(verdict));
      out.sample(labels, c.verdict == verdict ? 1.0 : 0.0);
    }
  }
  out.family("cosmic_channel_runtime_state", MetricType::gauge,
             "1 for the channel's runtime state (bound: no recent miss; violated: an HRT hop missed its bound), 0 for "
             "the other.");
  for (const auto& c : s.channels) {
    const auto* stats = find_stats(s, c.name);
    const auto current = stats ? stats->runtime_state : cosmic::RuntimeState::bound;
    for (const auto state : {cosmic::RuntimeState::bound, cosmic::RuntimeState::violated}) {
      Labels labels = channel_labels(c);
      labels.emplace_back("state", cosmic::to_string(state));
      out.sample(labels, current == state ? 1.0 : 0.0);
    }
  }
  out.family("cosmic_channel_violations", MetricType::counter,
             "Episodes of the violated runtime state since the channel was bound.");
  for (const auto& c : s.channels) {
    const auto* stats = find_stats(s, c.name);
    out.sample(channel_labels(c), stats ? stats->violations : 0);
  }
  out.family("cosmic_channel_forwarded_events", MetricType::counter,
             "Events accepted and queued for at least one subscriber segment.");
  for (const auto& c : s.channels) {
    const auto* stats = find_stats(s, c.name);
    out.sample(channel_labels(c), stats ? stats->forwarded : 0);
  }
}

// Admission's promises, as gauges next to what the router measures.
void render_channel_admission(Exposition& out, const MetricsSnapshot& s) {
  out.family("cosmic_channel_end_to_end_bound_seconds", MetricType::gauge,
             "Worst-case publisher-to-subscriber latency admission computed (+Inf: unbounded).");
  for (const auto& c : s.channels) out.sample(channel_labels(c), seconds_or_inf(c.end_to_end.latency));
  out.family("cosmic_channel_reaction_time_seconds", MetricType::gauge,
             "The channel's reaction_time (channels that declare one).");
  for (const auto& c : s.channels) {
    if (c.end_to_end.reaction_time) out.sample(channel_labels(c), seconds(*c.end_to_end.reaction_time));
  }
  out.family("cosmic_channel_slack_seconds", MetricType::gauge,
             "reaction_time minus the end-to-end bound; negative: the bound exceeds the reaction time.");
  for (const auto& c : s.channels) {
    if (c.end_to_end.reaction_time) {
      out.sample(channel_labels(c), seconds(*c.end_to_end.reaction_time) - seconds_or_inf(c.end_to_end.latency));
    }
  }
  out.family("cosmic_channel_temp_validity_seconds", MetricType::gauge,
             "The channel's temp_validity (channels that declare one).");
  for (const auto& c : s.channels) {
    if (c.end_to_end.temp_validity) out.sample(channel_labels(c), seconds(*c.end_to_end.temp_validity));
  }
}

void render_hop_admission(Exposition& out, const std::vector<HopView>& hops) {
  out.family(
      "cosmic_channel_hop_latency_bound_seconds", MetricType::gauge,
      "Worst-case latency admission counts for this hop (CAN: response time; IP: latency_bound; +Inf: unbounded).");
  for (const auto& h : hops) out.sample(hop_labels(h), seconds_or_inf(h.hop->latency));
  out.family(
      "cosmic_channel_hop_response_time_seconds", MetricType::gauge,
      "Predicted worst-case CAN response time R of the channel's frame on this hop (CAN hops only; +Inf: unbounded).");
  for (const auto& h : hops) {
    if (h.hop->can) out.sample(hop_labels(h), seconds_or_inf(h.hop->can->response_time));
  }
}

void render_hop_counters(Exposition& out, const std::vector<HopView>& hops) {
  out.family("cosmic_channel_received_events", MetricType::counter,
             "Events of the channel received on a publisher segment.");
  for (const auto& h : hops) out.sample(hop_labels(h), h.counters ? h.counters->rx : 0);
  out.family("cosmic_channel_sent_events", MetricType::counter, "Events of the channel sent on a subscriber segment.");
  for (const auto& h : hops) out.sample(hop_labels(h), h.counters ? h.counters->tx : 0);
  out.family("cosmic_channel_dropped_events", MetricType::counter,
             "Events of the channel dropped on this segment, by reason.");
  for (const auto& h : hops) {
    for (std::size_t r = 0; r < cosmic::kDropReasonCount; ++r) {
      Labels labels = hop_labels(h);
      labels.emplace_back("reason", cosmic::to_string(static_cast<cosmic::DropReason>(r)));
      out.sample(labels, h.counters ? h.counters->dropped[r] : 0);
    }
  }
  out.family("cosmic_channel_omitted_events", MetricType::counter,
             "Events the publisher sent that never arrived on this segment, by the gaps in its end-to-end counter.");
  for (const auto& h : hops) out.sample(hop_labels(h), h.counters ? h.counters->omitted : 0);
  out.family("cosmic_channel_omission_excess", MetricType::counter,
             "Gaps in the end-to-end counter on this segment longer than the channel's omission degree.");
  for (const auto& h : hops) out.sample(hop_labels(h), h.counters ? h.counters->omission_excess : 0);
}

// Egress hops (subscriber segments) carry the measured residence.
std::vector<std::pair<const HopView*, const cosmic::HopRuntimeSnapshot*>> egress_of(const std::vector<HopView>& hops) {
  std::vector<std::pair<const HopView*, const cosmic::HopRuntimeSnapshot*>> out;
  for (const auto& h : hops) {
    if (h.counters && h.counters->egress) out.emplace_back(&h, &*h.counters->egress);
  }
  return out;
}

void render_residence(Exposition& out, const std::vector<HopView>& hops) {
  const auto egress = egress_of(hops);
  out.family("cosmic_channel_residence_seconds", MetricType::histogram,
             "Time from the event's arrival at the gateway to the end of its send on this subscriber segment.");
  for (const auto& [h, e] : egress)
    out.histogram(hop_labels(*h), residence_bucket_bounds(), rebucket_residence(e->residence_buckets));
  // Gauges of their own: a "quantile" label belongs to summaries, which these are not.
  const std::pair<const char*, cosmic::Nanos cosmic::HopRuntimeSnapshot::*> quantiles[] = {
      {"cosmic_channel_residence_p50_seconds", &cosmic::HopRuntimeSnapshot::residence_p50},
      {"cosmic_channel_residence_p99_seconds", &cosmic::HopRuntimeSnapshot::residence_p99},
      {"cosmic_channel_residence_p999_seconds", &cosmic::HopRuntimeSnapshot::residence_p999}};
  for (const auto& [name, field] : quantiles) {
    out.family(name, MetricType::gauge,
               "Residence quantile since the channel was bound (upper end of the router's fine bucket).");
    for (const auto& [h, e] : egress) out.sample(hop_labels(*h), seconds(e->*field));
  }
  out.family("cosmic_channel_residence_max_seconds", MetricType::gauge,
             "Longest residence since the channel was bound.");
  for (const auto& [h, e] : egress) out.sample(hop_labels(*h), seconds(e->residence_max));
  out.family("cosmic_channel_residence_misses", MetricType::counter,
             "Events whose residence exceeded gateway.residence_bound.");
  for (const auto& [h, e] : egress) out.sample(hop_labels(*h), e->residence_miss);
  out.family("cosmic_channel_deadline_misses", MetricType::counter,
             "Events whose age when sent on this segment exceeded the channel's reaction_time.");
  for (const auto& [h, e] : egress) out.sample(hop_labels(*h), e->deadline_miss);
}

}  // namespace

const std::vector<double>& residence_bucket_bounds() {
  static const std::vector<double> bounds = {5e-6, 10e-6, 25e-6, 50e-6, 100e-6, 250e-6, 500e-6, 1e-3, 2.5e-3,
                                             5e-3, 10e-3, 25e-3, 50e-3, 100e-3, 250e-3, 500e-3, 1.0};
  return bounds;
}

std::vector<std::uint64_t> rebucket_residence(const std::vector<std::uint64_t>& source) {
  const auto& bounds = residence_bucket_bounds();
  std::vector<std::uint64_t> counts(bounds.size() + 1, 0);
  // Compared in whole nanoseconds: 10 us must hold a bucket ending at exactly 10000 ns.
  std::vector<std::uint64_t> bounds_ns;
  bounds_ns.reserve(bounds.size());
  for (const double bound : bounds) bounds_ns.push_back(static_cast<std::uint64_t>(std::llround(bound * 1e9)));
  for (std::size_t i = 0; i < source.size(); ++i) {
    const std::uint64_t upper = cosmic::LatencyHistogram::upper_bound_of(i);
    const auto slot = std::lower_bound(bounds_ns.begin(), bounds_ns.end(), upper) - bounds_ns.begin();
    counts[static_cast<std::size_t>(slot)] += source[i];
  }
  for (std::size_t i = 1; i < counts.size(); ++i) counts[i] += counts[i - 1];
  return counts;
}

// Present only while the gateway is in a federation (gateway.federation).
void render_federation(Exposition& out, const FederationSnapshot& f) {
  if (!f.enabled) return;
  out.family("cosmic_federation_peers", MetricType::gauge,
             "Other gateways of the federation by state (alive, lost, left).");
  for (const char* state : {"alive", "lost", "left"}) {
    const auto count = std::count_if(f.peers.begin(), f.peers.end(), [&](const auto& p) { return p.state == state; });
    out.sample({{"state", state}}, static_cast<std::uint64_t>(count));
  }
  out.family("cosmic_federation_peer_last_heard_seconds", MetricType::gauge,
             "Time since the last announcement or liveliness change of each known gateway.");
  for (const auto& p : f.peers)
    out.sample({{"peer", p.name}, {"id", p.id}, {"state", p.state}}, p.last_heard_age_seconds);
  out.family("cosmic_federation_messages_received", MetricType::counter,
             "Federation messages received (announcements and liveliness).");
  out.sample({}, f.view.received);
  out.family("cosmic_federation_announcements_refused", MetricType::counter,
             "Announcements refused as malformed, out of range or claiming another gateway's identity.");
  out.sample({}, f.view.refused);
  out.family("cosmic_federation_messages_dropped", MetricType::counter,
             "Federation messages dropped by a full queue (a flood).");
  out.sample({}, f.link.dropped);
  out.family("cosmic_federation_announcements_published", MetricType::counter, "This gateway's announcements written.");
  out.sample({}, f.link.published);
}

// Present while cosmicd has a recorder (a recording: section; docs/recording.md).
void render_recording(Exposition& out, const std::optional<cosmic::RecorderStatus>& recording) {
  if (!recording) return;
  const cosmic::RecorderStatus& r = *recording;
  out.family("cosmic_record_active", MetricType::gauge, "1 while the recording is on.");
  out.sample({}, static_cast<std::uint64_t>(r.recording ? 1 : 0));
  out.family("cosmic_record_messages", MetricType::counter, "Events written into recordings.");
  out.sample({}, r.messages);
  out.family("cosmic_record_bytes", MetricType::counter, "Bytes written into recordings.");
  out.sample({}, r.bytes);
  out.family("cosmic_record_files", MetricType::counter, "Recordings finished.");
  out.sample({}, r.files);
  out.family("cosmic_record_dropped", MetricType::counter,
             "Events of recorded channels not recorded, by reason: queue_full (the writer fell behind), "
             "not_written (no file could be written), invalid.");
  out.sample({{"reason", "queue_full"}}, r.dropped_full);
  out.sample({{"reason", "not_written"}}, r.dropped_failed);
  out.sample({{"reason", "invalid"}}, r.dropped_invalid);
  out.family("cosmic_record_queued_bytes", MetricType::gauge, "Bytes of events waiting for the writer.");
  out.sample({}, static_cast<std::uint64_t>(r.queued_bytes));
}

std::string render_metrics(const MetricsSnapshot& snapshot, ExpositionFormat format) {
  Exposition out(format);
  render_gateway(out, snapshot);
  render_segment_health(out, snapshot);
  render_segment_counters(out, snapshot);
  render_channel_state(out, snapshot);
  render_channel_admission(out, snapshot);
  const auto hops = hop_views(snapshot);
  render_hop_admission(out, hops);
  render_hop_counters(out, hops);
  render_residence(out, hops);
  render_federation(out, snapshot.federation);
  render_recording(out, snapshot.recording);
  return out.finish();
}

}  // namespace cosmicd

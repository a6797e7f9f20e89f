// The /metrics document rendered from a hand-made snapshot: names, labels, values, formats.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/router_stats.hpp"
#include "metrics_render.hpp"

namespace cosmicd {
namespace {

using cosmic::Nanos;

cosmic::SegmentInfo segment(const std::string& name, cosmic::SegmentType type, cosmic::SegmentHealth health) {
  cosmic::SegmentInfo info;
  info.spec.name = name;
  info.spec.type = type;
  info.spec.max_utilization = 0.7;
  info.health.state = health;
  info.utilization = 0.25;
  info.channels = 1;
  info.unrouted = 3;
  info.adapter.received = 100;
  info.adapter.sent = 90;
  info.adapter.receive_errors = 1;
  info.adapter.send_errors = 2;
  info.adapter.overflow_drops = 4;
  info.adapter.backlog = 5;
  return info;
}

cosmic::HopReport hop(const std::string& segment, cosmic::HopRole role, std::optional<Nanos> latency) {
  cosmic::HopReport out;
  out.segment = segment;
  out.role = role;
  out.latency = latency;
  return out;
}

// Residences of 3, 3, 7, 40 us and 2 ms through the router's own histogram.
std::vector<std::uint64_t> sample_buckets() {
  cosmic::LatencyHistogram histogram;
  for (const std::int64_t us : {3, 3, 7, 40, 2000}) histogram.record(Nanos(us * 1000));
  std::vector<std::uint64_t> buckets;
  for (std::size_t i = 0; i < cosmic::LatencyHistogram::kBuckets; ++i) buckets.push_back(histogram.bucket_count(i));
  return buckets;
}

// Channel "distance" (hrt) from body-can (CAN, R = 1.5 ms) to lan; channel "plot" (nrt, unbounded).
MetricsSnapshot robot() {
  MetricsSnapshot s;
  s.gateway_name = "q-robot";
  s.gateway_id = "00000000000000ab";
  s.uptime_seconds = 12.5;
  s.residence_bound = Nanos(500'000);
  s.router_queued = 2;
  s.router_handled = 777;
  s.segments = {segment("body-can", cosmic::SegmentType::can, cosmic::SegmentHealth::up),
                segment("lan", cosmic::SegmentType::dds, cosmic::SegmentHealth::down)};

  cosmic::ChannelReport distance;
  distance.name = "distance";
  distance.cls = cosmic::ChannelClass::hrt;
  distance.hops = {hop("body-can", cosmic::HopRole::publisher, Nanos(1'500'000)),
                   hop("lan", cosmic::HopRole::subscriber, Nanos(2'000'000))};
  distance.hops[0].can = cosmic::CanHopPlan{};
  distance.hops[0].can->response_time = Nanos(1'500'000);
  distance.end_to_end.latency = Nanos(4'000'000);
  distance.end_to_end.reaction_time = Nanos(5'000'000);
  distance.end_to_end.temp_validity = Nanos(50'000'000);

  cosmic::ChannelReport plot;
  plot.name = "plot";
  plot.cls = cosmic::ChannelClass::nrt;
  plot.verdict = cosmic::Verdict::degraded;
  plot.hops = {hop("lan", cosmic::HopRole::publisher, std::nullopt),
               hop("body-can", cosmic::HopRole::subscriber, std::nullopt)};
  plot.end_to_end.reaction_time = Nanos(10'000'000);
  s.channels = {distance, plot};

  cosmic::ChannelStatsSnapshot stats;
  stats.name = "distance";
  stats.forwarded = 41;
  stats.runtime_state = cosmic::RuntimeState::violated;
  stats.violations = 1;
  cosmic::SegmentCountersSnapshot rx;
  rx.segment = "body-can";
  rx.rx = 42;
  rx.dropped[static_cast<std::size_t>(cosmic::DropReason::expired)] = 1;
  cosmic::SegmentCountersSnapshot tx;
  tx.segment = "lan";
  tx.tx = 40;
  tx.dropped[static_cast<std::size_t>(cosmic::DropReason::queue_full)] = 7;
  cosmic::HopRuntimeSnapshot egress;
  egress.events = 5;
  egress.residence_p50 = Nanos(3071);
  egress.residence_p99 = Nanos(2'000'000);
  egress.residence_p999 = Nanos(2'000'000);
  egress.residence_max = Nanos(2'000'000);
  egress.residence_miss = 1;
  egress.deadline_miss = 2;
  egress.residence_buckets = sample_buckets();
  tx.egress = egress;
  stats.segments = {rx, tx};
  s.stats = {stats};
  return s;
}

std::string text() { return render_metrics(robot(), ExpositionFormat::prometheus_text); }

bool has_line(const std::string& document, const std::string& line) {
  return document.find("\n" + line + "\n") != std::string::npos || document.rfind(line + "\n", 0) == 0;
}

#define EXPECT_LINE(document, line) EXPECT_TRUE(has_line(document, line)) << "missing line: " << line

TEST(MetricsRender, GatewayAndRouter) {
  const std::string m = text();
  EXPECT_LINE(m, "cosmic_gateway_info{gateway=\"q-robot\",id=\"00000000000000ab\"} 1");
  EXPECT_LINE(m, "cosmic_gateway_uptime_seconds 12.5");
  EXPECT_LINE(m, "cosmic_gateway_residence_bound_seconds 0.0005");
  EXPECT_LINE(m, "cosmic_router_queued_events 2");
  EXPECT_LINE(m, "cosmic_router_handled_events_total 777");
}

// Only with a recorder; its counters by name and drop reason.
TEST(MetricsRender, RecordingCountersAndDropsByReason) {
  EXPECT_EQ(text().find("cosmic_record_"), std::string::npos);
  MetricsSnapshot s = robot();
  cosmic::RecorderStatus r;
  r.recording = true;
  r.messages = 1200;
  r.bytes = 64000;
  r.files = 2;
  r.dropped_full = 7;
  r.dropped_failed = 3;
  r.dropped_invalid = 1;
  r.queued_bytes = 4096;
  s.recording = r;
  const std::string m = render_metrics(s, ExpositionFormat::prometheus_text);
  EXPECT_LINE(m, "cosmic_record_active 1");
  EXPECT_LINE(m, "cosmic_record_messages_total 1200");
  EXPECT_LINE(m, "cosmic_record_bytes_total 64000");
  EXPECT_LINE(m, "cosmic_record_files_total 2");
  EXPECT_LINE(m, "cosmic_record_dropped_total{reason=\"queue_full\"} 7");
  EXPECT_LINE(m, "cosmic_record_dropped_total{reason=\"not_written\"} 3");
  EXPECT_LINE(m, "cosmic_record_dropped_total{reason=\"invalid\"} 1");
  EXPECT_LINE(m, "cosmic_record_queued_bytes 4096");
}

TEST(MetricsRender, SegmentsHealthLoadAndAdapterCounters) {
  const std::string m = text();
  EXPECT_LINE(m, "cosmic_segment_up{segment=\"body-can\",type=\"can\"} 1");
  EXPECT_LINE(m, "cosmic_segment_up{segment=\"lan\",type=\"dds\"} 0");
  EXPECT_LINE(m, "cosmic_segment_health{segment=\"lan\",type=\"dds\",state=\"down\"} 1");
  EXPECT_LINE(m, "cosmic_segment_health{segment=\"lan\",type=\"dds\",state=\"up\"} 0");
  EXPECT_LINE(m, "cosmic_segment_reserved_utilization_ratio{segment=\"lan\",type=\"dds\"} 0.25");
  EXPECT_LINE(m, "cosmic_segment_max_utilization_ratio{segment=\"lan\",type=\"dds\"} 0.7");
  EXPECT_LINE(m, "cosmic_segment_unrouted_events_total{segment=\"lan\",type=\"dds\"} 3");
  EXPECT_LINE(m, "cosmic_segment_received_messages_total{segment=\"lan\",type=\"dds\"} 100");
  EXPECT_LINE(m, "cosmic_segment_sent_messages_total{segment=\"lan\",type=\"dds\"} 90");
  EXPECT_LINE(m, "cosmic_segment_receive_errors_total{segment=\"lan\",type=\"dds\"} 1");
  EXPECT_LINE(m, "cosmic_segment_send_errors_total{segment=\"lan\",type=\"dds\"} 2");
  EXPECT_LINE(m, "cosmic_segment_overflow_drops_total{segment=\"lan\",type=\"dds\"} 4");
  EXPECT_LINE(m, "cosmic_segment_send_backlog_messages{segment=\"lan\",type=\"dds\"} 5");
}

// Only a segment whose filter drops the gateway's own datagrams (LCM, own_datagrams: drop) has
// the counter; the others have no sample rather than a 0 that would claim a filter.
TEST(MetricsRender, OwnDatagramsDroppedOnlyWhereTheFilterDropsThem) {
  MetricsSnapshot s = robot();
  cosmic::SegmentInfo viz = segment("viz", cosmic::SegmentType::lcm, cosmic::SegmentHealth::up);
  viz.adapter.transport.push_back(cosmic::TransportCounter{"own_datagrams_dropped", 1234});
  s.segments.push_back(viz);
  const std::string m = render_metrics(s, ExpositionFormat::prometheus_text);
  EXPECT_LINE(m, "cosmic_segment_own_datagrams_dropped_total{segment=\"viz\",type=\"lcm\"} 1234");
  EXPECT_EQ(m.find("cosmic_segment_own_datagrams_dropped_total{segment=\"lan\""), std::string::npos);
  EXPECT_EQ(m.find("cosmic_segment_own_datagrams_dropped_total{segment=\"body-can\""), std::string::npos);
}

// `unauthenticated` counts messages on an LCM segment and participants on a secure DDS segment:
// each in a family of its own, so no sum mixes the two.
TEST(MetricsRender, UnauthenticatedMessagesAndParticipantsAreFamiliesApart) {
  MetricsSnapshot s = robot();
  cosmic::SegmentInfo viz = segment("viz", cosmic::SegmentType::lcm, cosmic::SegmentHealth::up);
  viz.adapter.transport.push_back(cosmic::TransportCounter{"unauthenticated", 7});
  s.segments.push_back(viz);
  cosmic::SegmentInfo secure = segment("secure", cosmic::SegmentType::dds, cosmic::SegmentHealth::up);
  secure.adapter.transport.push_back(cosmic::TransportCounter{"unauthenticated", 2});
  s.segments.push_back(secure);
  const std::string m = render_metrics(s, ExpositionFormat::prometheus_text);
  EXPECT_LINE(m, "cosmic_segment_unauthenticated_total{segment=\"viz\",type=\"lcm\"} 7");
  EXPECT_LINE(m, "cosmic_segment_unauthenticated_participants_total{segment=\"secure\",type=\"dds\"} 2");
  EXPECT_EQ(m.find("cosmic_segment_unauthenticated_total{segment=\"secure\""), std::string::npos);
  EXPECT_EQ(m.find("cosmic_segment_unauthenticated_participants_total{segment=\"viz\""), std::string::npos);
  EXPECT_EQ(m.find("cosmic_segment_unauthenticated_participants_total{segment=\"lan\""), std::string::npos);
}

TEST(MetricsRender, PerHopCountersAndEveryDropReason) {
  const std::string m = text();
  const std::string in = "channel=\"distance\",class=\"hrt\",segment=\"body-can\",role=\"publisher\"";
  const std::string out = "channel=\"distance\",class=\"hrt\",segment=\"lan\",role=\"subscriber\"";
  EXPECT_LINE(m, "cosmic_channel_received_events_total{" + in + "} 42");
  EXPECT_LINE(m, "cosmic_channel_sent_events_total{" + out + "} 40");
  EXPECT_LINE(m, "cosmic_channel_dropped_events_total{" + in + ",reason=\"expired\"} 1");
  EXPECT_LINE(m, "cosmic_channel_dropped_events_total{" + out + ",reason=\"queue_full\"} 7");
  for (std::size_t r = 0; r < cosmic::kDropReasonCount; ++r) {
    const std::string reason = cosmic::to_string(static_cast<cosmic::DropReason>(r));
    EXPECT_NE(m.find("cosmic_channel_dropped_events_total{" + out + ",reason=\"" + reason + "\"}"), std::string::npos)
        << reason;
  }
  // A channel the router has no counters for yet still shows zeros.
  EXPECT_LINE(
      m, "cosmic_channel_sent_events_total{channel=\"plot\",class=\"nrt\",segment=\"body-can\",role=\"subscriber\"} 0");
  EXPECT_LINE(m, "cosmic_channel_forwarded_events_total{channel=\"distance\",class=\"hrt\"} 41");
}

TEST(MetricsRender, ResidenceHistogramIsRebucketedCumulatively) {
  const std::string m = text();
  const std::string out =
      "cosmic_channel_residence_seconds_bucket{channel=\"distance\",class=\"hrt\",segment=\"lan\",role=\"subscriber\","
      "le=\"";
  const std::map<double, int> expected = {{5e-6, 2}, {10e-6, 3},  {25e-6, 3}, {50e-6, 4},
                                          {1e-3, 4}, {2.5e-3, 5}, {1.0, 5}};
  for (const auto& [le, count] : expected) EXPECT_LINE(m, out + format_number(le) + "\"} " + std::to_string(count));
  EXPECT_LINE(m, out + "+Inf\"} 5");
  EXPECT_LINE(m,
              "cosmic_channel_residence_seconds_count{channel=\"distance\",class=\"hrt\",segment=\"lan\",role="
              "\"subscriber\"} 5");
  // Only egress hops carry residence.
  EXPECT_EQ(m.find("cosmic_channel_residence_seconds_bucket{channel=\"distance\",class=\"hrt\",segment=\"body-can\""),
            std::string::npos);
}

TEST(MetricsRender, ResidenceQuantilesAndMisses) {
  const std::string m = text();
  const std::string out = "channel=\"distance\",class=\"hrt\",segment=\"lan\",role=\"subscriber\"";
  EXPECT_LINE(m, "cosmic_channel_residence_p50_seconds{" + out + "} " + format_number(3071e-9));
  EXPECT_LINE(m, "cosmic_channel_residence_p99_seconds{" + out + "} 0.002");
  EXPECT_LINE(m, "cosmic_channel_residence_p999_seconds{" + out + "} 0.002");
  EXPECT_LINE(m, "cosmic_channel_residence_max_seconds{" + out + "} 0.002");
  EXPECT_LINE(m, "cosmic_channel_residence_misses_total{" + out + "} 1");
  EXPECT_LINE(m, "cosmic_channel_deadline_misses_total{" + out + "} 2");
}

TEST(MetricsRender, VerdictAndRuntimeStateAreStateSets) {
  const std::string m = text();
  EXPECT_LINE(m, "cosmic_channel_verdict{channel=\"plot\",class=\"nrt\",verdict=\"degraded\"} 1");
  EXPECT_LINE(m, "cosmic_channel_verdict{channel=\"plot\",class=\"nrt\",verdict=\"bound\"} 0");
  EXPECT_LINE(m, "cosmic_channel_runtime_state{channel=\"distance\",class=\"hrt\",state=\"violated\"} 1");
  EXPECT_LINE(m, "cosmic_channel_runtime_state{channel=\"distance\",class=\"hrt\",state=\"bound\"} 0");
  EXPECT_LINE(m, "cosmic_channel_runtime_state{channel=\"plot\",class=\"nrt\",state=\"bound\"} 1");
  EXPECT_LINE(m, "cosmic_channel_violations_total{channel=\"distance\",class=\"hrt\"} 1");
}

// A channel a transport refused (issue 9) is admitted but not carried: its own state of the set.
TEST(MetricsRender, AChannelATransportRefusedIsFailed) {
  MetricsSnapshot s = robot();
  s.channels[1].verdict = cosmic::Verdict::failed;
  const std::string m = render_metrics(s, ExpositionFormat::prometheus_text);
  EXPECT_LINE(m, "cosmic_channel_verdict{channel=\"plot\",class=\"nrt\",verdict=\"failed\"} 1");
  EXPECT_LINE(m, "cosmic_channel_verdict{channel=\"plot\",class=\"nrt\",verdict=\"degraded\"} 0");
  EXPECT_LINE(m, "cosmic_channel_verdict{channel=\"distance\",class=\"hrt\",verdict=\"failed\"} 0");
}

TEST(MetricsRender, AdmissionNumbersAndSlack) {
  const std::string m = text();
  EXPECT_LINE(m, "cosmic_channel_end_to_end_bound_seconds{channel=\"distance\",class=\"hrt\"} 0.004");
  EXPECT_LINE(m, "cosmic_channel_reaction_time_seconds{channel=\"distance\",class=\"hrt\"} 0.005");
  EXPECT_LINE(m, "cosmic_channel_slack_seconds{channel=\"distance\",class=\"hrt\"} " + format_number(0.005 - 0.004));
  EXPECT_LINE(m, "cosmic_channel_temp_validity_seconds{channel=\"distance\",class=\"hrt\"} 0.05");
  EXPECT_LINE(m, "cosmic_channel_end_to_end_bound_seconds{channel=\"plot\",class=\"nrt\"} +Inf");
  EXPECT_LINE(m, "cosmic_channel_slack_seconds{channel=\"plot\",class=\"nrt\"} -Inf");
  EXPECT_LINE(m,
              "cosmic_channel_hop_response_time_seconds{channel=\"distance\",class=\"hrt\",segment=\"body-can\",role="
              "\"publisher\"} 0.0015");
  EXPECT_LINE(m,
              "cosmic_channel_hop_latency_bound_seconds{channel=\"distance\",class=\"hrt\",segment=\"lan\",role="
              "\"subscriber\"} 0.002");
  EXPECT_LINE(m,
              "cosmic_channel_hop_latency_bound_seconds{channel=\"plot\",class=\"nrt\",segment=\"lan\",role="
              "\"publisher\"} +Inf");
  // No CAN plan, no response time.
  EXPECT_EQ(m.find("cosmic_channel_hop_response_time_seconds{channel=\"plot\""), std::string::npos);
}

TEST(MetricsRender, LabelValuesAreEscaped) {
  MetricsSnapshot s = robot();
  s.gateway_name = "a\"b\\c\nd";
  EXPECT_LINE(render_metrics(s, ExpositionFormat::prometheus_text),
              "cosmic_gateway_info{gateway=\"a\\\"b\\\\c\\nd\",id=\"00000000000000ab\"} 1");
}

// Families as declared by "# TYPE" lines, checking that every sample follows its own family's
// declaration (the formats require each family's samples to be contiguous).
std::map<std::string, std::string> families(const std::string& document, ExpositionFormat format) {
  std::map<std::string, std::string> types;
  std::string current;
  std::string current_type;
  std::istringstream lines(document);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("# TYPE ", 0) == 0) {
      std::istringstream words(line.substr(7));
      words >> current >> current_type;
      EXPECT_TRUE(current_type == "counter" || current_type == "gauge" || current_type == "histogram") << line;
      EXPECT_TRUE(types.emplace(current, current_type).second) << "declared twice: " << current;
      continue;
    }
    if (line.rfind("# ", 0) == 0) continue;
    // NAME{LABELS} VALUE or NAME VALUE; no regex: GCC 12 warns inside <regex> under sanitizers.
    const auto name_end = line.find_first_of("{ ");
    const auto value_start = line.rfind(' ');
    if (name_end == std::string::npos || name_end == 0 || value_start + 1 >= line.size()) {
      ADD_FAILURE() << "not a metrics line: " << line;
      continue;
    }
    const std::string base = line.substr(0, name_end);
    EXPECT_EQ(base.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_"), std::string::npos) << line;
    const std::string counter_family =
        format == ExpositionFormat::openmetrics && base.size() > 6 ? base.substr(0, base.size() - 6) : base;
    const bool ok = base == current || (current_type == "counter" && counter_family == current) ||
                    (current_type == "histogram" && (base == current + "_bucket" || base == current + "_count"));
    EXPECT_TRUE(ok) << "sample " << base << " outside its family (current: " << current << ")";
  }
  return types;
}

TEST(MetricsRender, PrometheusTextDeclaresCountersWithTotal) {
  const auto types = families(text(), ExpositionFormat::prometheus_text);
  EXPECT_EQ(types.at("cosmic_channel_sent_events_total"), "counter");
  EXPECT_EQ(types.at("cosmic_channel_residence_seconds"), "histogram");
  for (const auto& [name, type] : types) {
    EXPECT_EQ(type == "counter", name.ends_with("_total")) << name;
  }
}

TEST(MetricsRender, OpenMetricsDeclaresCounterFamiliesAndEnds) {
  const std::string m = render_metrics(robot(), ExpositionFormat::openmetrics);
  const auto types = families(m, ExpositionFormat::openmetrics);
  EXPECT_EQ(types.at("cosmic_channel_sent_events"), "counter");
  EXPECT_LINE(
      m, "cosmic_channel_sent_events_total{channel=\"distance\",class=\"hrt\",segment=\"lan\",role=\"subscriber\"} 40");
  EXPECT_TRUE(m.ends_with("\n# EOF\n"));
  EXPECT_EQ(format_for_accept("application/openmetrics-text;version=1.0.0,text/plain;version=0.0.4;q=0.5"),
            ExpositionFormat::openmetrics);
  EXPECT_EQ(format_for_accept("*/*"), ExpositionFormat::prometheus_text);
}

// Every family the renderer emits is described in docs/metrics.md.
TEST(MetricsRender, EveryFamilyIsDocumented) {
  std::ifstream file(std::string(cosmic::build_paths::source_dir) + "/docs/metrics.md");
  ASSERT_TRUE(file) << "docs/metrics.md is missing";
  std::stringstream docs;
  docs << file.rdbuf();
  for (const auto& [name, type] : families(text(), ExpositionFormat::prometheus_text)) {
    EXPECT_NE(docs.str().find("`" + name + "`"), std::string::npos) << name << " is not in docs/metrics.md";
  }
}

}  // namespace
}  // namespace cosmicd

#include "cosmic/upstream_path.hpp"

#include <algorithm>
#include <limits>

namespace cosmic {
namespace {

std::string text_of(const std::optional<Nanos>& value) { return value ? format_duration(*value) : std::string("none"); }

// How `upstream` defines the subject differently: each difference with what it does to the verdict.
std::vector<std::pair<Verdict, std::string>> definition_differences(const ChannelSpec& channel,
                                                                    const UpstreamPath& upstream) {
  std::vector<std::pair<Verdict, std::string>> out;
  const std::string there = " at gateway " + upstream.gateway + " (channel " + upstream.channel + ")";
  if (upstream.period && (!channel.period || *upstream.period < *channel.period)) {
    out.emplace_back(consequence_of("utilization", channel.cls), "period " + format_duration(*upstream.period) + there +
                                                                     " < " + text_of(channel.period) +
                                                                     " here: more events than admitted");
  }
  if (upstream.payload > channel.payload) {
    out.emplace_back(consequence_of("frame_fit", channel.cls), "payload " + std::to_string(upstream.payload) + " B" +
                                                                   there + " > " + std::to_string(channel.payload) +
                                                                   " B here");
  }
  if (upstream.cls != channel.cls) {
    out.emplace_back(Verdict::degraded,
                     std::string("class ") + to_string(upstream.cls) + there + ", " + to_string(channel.cls) + " here");
  }
  if (upstream.reaction_time != channel.reaction_time) {
    out.emplace_back(Verdict::degraded, "reaction_time " + text_of(upstream.reaction_time) + there + ", " +
                                            text_of(channel.reaction_time) + " here");
  }
  if (upstream.temp_validity != channel.temp_validity) {
    out.emplace_back(Verdict::degraded, "temp_validity " + text_of(upstream.temp_validity) + there + ", " +
                                            text_of(channel.temp_validity) + " here");
  }
  return out;
}

}  // namespace

void apply_upstream(const ChannelSpec& channel, const UpstreamPath& upstream, ChannelReport& report) {
  auto worsen = [&](Verdict v, std::string reason) {
    report.verdict = std::max(report.verdict, v);
    report.reasons.push_back(std::move(reason));
  };
  report.upstream = upstream.hops;
  EndToEnd& e2e = report.end_to_end;
  e2e.upstream = upstream.age;
  e2e.local = e2e.latency;
  e2e.latency = upstream.age && e2e.local ? std::optional<Nanos>(*upstream.age + *e2e.local) : std::nullopt;
  const double whole = e2e.latency ? to_seconds(*e2e.latency) : std::numeric_limits<double>::infinity();
  const std::string path = "end-to-end latency through gateway " + upstream.gateway + " " +
                           (e2e.latency ? format_seconds(whole) : std::string("unbounded"));
  if (channel.cls != ChannelClass::nrt && channel.reaction_time && e2e.latency_ok &&
      whole > to_seconds(*channel.reaction_time)) {
    e2e.latency_ok = false;
    worsen(consequence_of("latency", channel.cls),
           path + " > reaction_time " + format_duration(*channel.reaction_time));
  }
  if (channel.temp_validity && e2e.validity_ok && whole >= to_seconds(*channel.temp_validity)) {
    e2e.validity_ok = false;
    worsen(consequence_of("validity", channel.cls),
           path + " >= temp_validity " + format_duration(*channel.temp_validity) + ": events would arrive stale");
  }
  if (upstream.violated) {
    worsen(consequence_of("latency", channel.cls), "gateway " + upstream.gateway + " reports channel " +
                                                       upstream.channel +
                                                       " violated at run time: the path's bound does not hold now");
  }
  for (auto& [verdict, reason] : definition_differences(channel, upstream)) worsen(verdict, std::move(reason));
}

}  // namespace cosmic

#include "diagram_status.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "cosmic/knowledge_base.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

std::string spaced_micros(double seconds) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.0f us", seconds * 1e6);
  return buffer;
}

// A count from the gateway's answer; absent or not a count reads as 0 rather than failing the
// whole diagram over one field.
std::uint64_t count(const Json& object, const char* key) {
  const auto found = object.find(key);
  return found != object.end() && found->is_number_unsigned() ? found->get<std::uint64_t>() : 0;
}

std::optional<cosmic::Nanos> duration(const Json& object, const char* key) {
  const auto found = object.find(key);
  if (found == object.end() || !found->is_number() || !std::isfinite(found->get<double>())) return std::nullopt;
  return cosmic::Nanos(static_cast<std::int64_t>(std::llround(found->get<double>() * 1e9)));
}

// "queue_full=3 expired=1", or "" when nothing was dropped.
std::string drops(const Json& dropped, std::uint64_t& total) {
  std::string out;
  if (!dropped.is_object()) return out;
  for (const auto& [reason, value] : dropped.items()) {
    const std::uint64_t n = value.is_number_unsigned() ? value.get<std::uint64_t>() : 0;
    if (n == 0) continue;
    total += n;
    out += (out.empty() ? "" : " ") + reason + "=" + std::to_string(n);
  }
  return out;
}

ChannelStatus live_channel(const Json& c) {
  ChannelStatus s;
  s.verdict = c.value("verdict", "bound");
  s.violated = c.value("runtime_state", "bound") == "violated";
  s.end_to_end = duration(c, "predicted_end_to_end_s");
  s.reaction_time = duration(c, "reaction_time_s");
  const Json residence = c.value("residence", Json::object());
  s.counters.push_back("forwarded " + std::to_string(count(c, "forwarded")));
  if (residence.contains("p99_s") && residence["p99_s"].is_number()) {
    s.counters.push_back("p99 " + spaced_micros(residence["p99_s"].get<double>()));
    s.notes.push_back("residence p50 " + spaced_micros(residence.value("p50_s", 0.0)) + ", p99 " +
                      spaced_micros(residence["p99_s"].get<double>()) + ", max " +
                      spaced_micros(residence.value("max_s", 0.0)) + " (bound " +
                      spaced_micros(residence.value("bound_s", 0.0)) + ")");
  }
  std::uint64_t dropped = 0;
  for (const auto& seg : c.value("segments", Json::array())) {
    const std::string role = seg.value("role", "?") == "publisher" ? "P" : "S";
    std::string line = seg.value("segment", "?") + " " + role + ": rx " + std::to_string(count(seg, "rx")) + ", tx " +
                       std::to_string(count(seg, "tx"));
    const std::string reasons = drops(seg.value("dropped", Json::object()), dropped);
    if (!reasons.empty()) line += ", dropped " + reasons;
    s.notes.push_back(line);
  }
  if (dropped > 0) s.counters.push_back("dropped " + std::to_string(dropped));
  // A violation is worth its own words on the channel: how often, and which bound was missed.
  if (const std::uint64_t episodes = count(c, "violations"); episodes > 0 || s.violated) {
    s.counters.push_back(std::to_string(episodes) + " violation" + (episodes == 1 ? "" : "s"));
    s.notes.push_back("misses: residence " + std::to_string(count(c, "residence_miss")) + ", deadline " +
                      std::to_string(count(c, "deadline_miss")));
  }
  for (const auto& reason : c.value("reasons", Json::array())) {
    if (reason.is_string()) s.notes.push_back(reason.get<std::string>());
  }
  for (const auto& mismatch : c.value("mismatches", Json::array())) {
    if (mismatch.is_string()) s.notes.push_back("QoS mismatch: " + mismatch.get<std::string>());
  }
  return s;
}

}  // namespace

DiagramStatus offline_status(const cosmic::Config& config) {
  DiagramStatus out;
  for (const auto& c : cosmic::admit_all(config).channels) {
    ChannelStatus s;
    s.verdict = cosmic::to_string(c.verdict);
    s.end_to_end = c.end_to_end.latency;
    s.reaction_time = c.end_to_end.reaction_time;
    s.notes = c.reasons;
    out[c.name] = std::move(s);
  }
  return out;
}

DiagramStatus live_status(const Json& channels) {
  DiagramStatus out;
  if (!channels.is_array()) return out;
  for (const auto& c : channels) {
    if (c.is_object()) out[c.value("name", "")] = live_channel(c);
  }
  return out;
}

}  // namespace cosmicctl

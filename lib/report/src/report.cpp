#include "cosmic/report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "cosmic/can_wire.hpp"

namespace cosmic {
namespace {

nlohmann::json number_or_null(double value) {
  if (std::isinf(value) || std::isnan(value)) return nullptr;
  return value;
}

nlohmann::json seconds_or_null(const std::optional<Nanos>& value) {
  if (!value) return nullptr;
  return to_seconds(*value);
}

nlohmann::json to_json(const Check& check) {
  return {{"check", check.check}, {"value", number_or_null(check.value)}, {"limit", number_or_null(check.limit)},
          {"unit", check.unit},   {"relation", check.relation},           {"ok", check.ok}};
}

nlohmann::json to_json(const HopReport& hop) {
  nlohmann::json out{
      {"segment", hop.segment}, {"role", to_string(hop.role)}, {"latency_s", seconds_or_null(hop.latency)}};
  if (hop.can) {
    const CanHopPlan& can = *hop.can;
    if (can.native) {
      // The devices' own identifier: no priority field, TxNode or etag.
      out["can"] = {{"layout", "native"}, {"can_id", can.can_id}, {"extended", can.extended}};
    } else {
      const CanIdentifier fields = decode_can_id(can.can_id);  // TxNode and etag: same bits in both layouts
      out["can"] = {{"layout", can.profile == CanProfile::famouso ? "famouso" : "cosmic"},
                    {"priority", can.priority},
                    {"can_id", can.can_id},
                    {"extended", true},
                    {"tx_node", fields.tx_node},
                    {"etag", can.etag}};
    }
    out["can"].update({{"frame_bytes", can.frame_bytes},
                       {"frames_per_event", can.frames_per_event},
                       {"transmission_time_s", to_seconds(can.transmission)},
                       {"jitter_s", to_seconds(can.jitter)},
                       {"response_time_s", seconds_or_null(can.response_time)}});
    if (!can.native && can.profile == CanProfile::famouso)
      out["can"]["fragment"] = decode_famouso_id(can.can_id).fragment;
  }
  if (hop.dds) {
    out["dds"] = {
        {"topic", hop.dds->topic}, {"type", hop.dds->type}, {"layout", hop.dds->native ? "native" : "envelope"}};
    if (hop.dds->native) out["dds"]["representation"] = to_string(hop.dds->representation);
  }
  if (!hop.representation.empty()) out["representation"] = hop.representation;
  if (hop.security) {
    out["security"] = {{"scheme", hop.security->scheme}, {"bytes", hop.security->bytes}};
    out["security"]["time_s"] = hop.security->time ? nlohmann::json(to_seconds(*hop.security->time)) : nlohmann::json();
  }
  out["checks"] = nlohmann::json::array();
  for (const auto& check : hop.checks) out["checks"].push_back(to_json(check));
  if (!hop.background.empty()) {
    out["background"] = nlohmann::json::array();
    for (const auto& d : hop.background) {
      out["background"].push_back({{"name", d.name},
                                   {"can_id", d.can_id},
                                   {"extended", d.extended},
                                   {"delay_s", to_seconds(d.delay)},
                                   {"kind", d.blocking ? "blocking" : "interference"}});
    }
  }
  return out;
}

std::string check_value_text(const Check& check) {
  if (check.unit == "s") return format_seconds(check.value);
  if (check.unit == "ratio") return format_percent(check.value);
  if (check.unit == "B") return std::to_string(static_cast<long long>(check.value)) + " B";
  if (check.unit == "bool") return check.value >= 1.0 ? "yes" : "no";
  return std::to_string(static_cast<long long>(check.value));
}

std::string limit_text(const Check& check) {
  Check limit = check;
  limit.value = check.limit;
  return check_value_text(limit);
}

}  // namespace

std::string can_identifier_text(std::uint32_t can_id, CanProfile profile) {
  CanHopPlan plan;
  plan.can_id = can_id;
  plan.profile = profile;
  return can_identifier_text(plan);
}

std::string can_identifier_text(const CanHopPlan& plan) {
  const std::uint32_t can_id = plan.can_id;
  char text[96];
  if (plan.native) {
    std::snprintf(text, sizeof text, plan.extended ? "0x%08X (native, extended)" : "0x%03X (native, standard)", can_id);
  } else if (plan.profile == CanProfile::famouso) {
    const FamousoIdentifier id = decode_famouso_id(can_id);
    std::snprintf(text, sizeof text, "0x%08X (FAMOUSO layout: priority 0x%02X, fragment %d, TxNode %u, etag %u)",
                  can_id, static_cast<unsigned>(id.priority), id.fragment ? 1 : 0, static_cast<unsigned>(id.tx_node),
                  static_cast<unsigned>(id.etag));
  } else {
    const CanIdentifier id = decode_can_id(can_id);
    std::snprintf(text, sizeof text, "0x%08X (priority 0x%02X, TxNode %u, etag %u)", can_id,
                  static_cast<unsigned>(id.priority), static_cast<unsigned>(id.tx_node),
                  static_cast<unsigned>(id.etag));
  }
  return text;
}

std::string pad_column(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

nlohmann::json to_json(const ChannelReport& channel) {
  nlohmann::json out{{"name", channel.name},
                     {"class", to_string(channel.cls)},
                     {"verdict", to_string(channel.verdict)},
                     {"reasons", channel.reasons}};
  out["hops"] = nlohmann::json::array();
  for (const auto& hop : channel.hops) {
    out["hops"].push_back(to_json(hop));
    if (!channel.upstream.empty()) out["hops"].back()["gateway"] = channel.gateway;
  }
  const EndToEnd& e2e = channel.end_to_end;
  if (!channel.upstream.empty()) {
    // The path on other gateways before this one's (federation): each hop names its gateway.
    out["upstream"] = nlohmann::json::array();
    for (const PathHop& hop : channel.upstream) {
      out["upstream"].push_back({{"gateway", hop.gateway},
                                 {"segment", hop.segment},
                                 {"role", to_string(hop.role)},
                                 {"latency_s", seconds_or_null(hop.latency)}});
    }
  }
  out["end_to_end"] = {{"latency_s", seconds_or_null(e2e.latency)},
                       {"reaction_time_s", seconds_or_null(e2e.reaction_time)},
                       {"temp_validity_s", seconds_or_null(e2e.temp_validity)},
                       {"latency_ok", e2e.latency_ok},
                       {"validity_ok", e2e.validity_ok},
                       {"ok", e2e.ok()}};
  if (!channel.upstream.empty()) {
    out["end_to_end"]["upstream_s"] = seconds_or_null(e2e.upstream);
    out["end_to_end"]["local_s"] = seconds_or_null(e2e.local);
  }
  return out;
}

nlohmann::json to_json(const SegmentLoad& segment) {
  nlohmann::json out{{"name", segment.name},
                     {"type", to_string(segment.type)},
                     {"utilization", segment.utilization},
                     {"max_utilization", segment.max_utilization}};
  if (segment.type == SegmentType::can) {
    out["background"] = {{"utilization", segment.background}, {"frames", segment.background_frames}};
  }
  return out;
}

nlohmann::json to_json(const AdmissionReport& report) {
  nlohmann::json out{{"segments", nlohmann::json::array()}, {"channels", nlohmann::json::array()}};
  for (const auto& s : report.segments) out["segments"].push_back(to_json(s));
  for (const auto& c : report.channels) out["channels"].push_back(to_json(c));
  return out;
}

nlohmann::json to_json(const std::vector<ConfigError>& errors) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : errors) {
    out.push_back({{"file", e.file},
                   {"line", e.line},
                   {"column", e.column},
                   {"path", e.path},
                   {"message", e.message},
                   {"valid", e.valid},
                   {"text", e.to_string()}});
  }
  return out;
}

std::string render_text(const AdmissionReport& report) {
  std::ostringstream out;
  out << pad_column("SEGMENT", 16) << pad_column("TYPE", 6) << pad_column("UTILIZATION", 13) << pad_column("LIMIT", 8)
      << "BACKGROUND\n";
  for (const auto& s : report.segments) {
    const std::string background =
        s.background_frames ? format_percent(s.background) + " (" + std::to_string(s.background_frames) + " frames)"
                            : "-";
    out << pad_column(s.name, 16) << pad_column(to_string(s.type), 6) << pad_column(format_percent(s.utilization), 13)
        << pad_column(format_percent(s.max_utilization), 8) << background << "\n";
  }
  out << "\n"
      << pad_column("CHANNEL", 20) << pad_column("CLASS", 6) << pad_column("VERDICT", 10)
      << pad_column("END-TO-END", 12) << "DETAILS\n";
  for (const auto& c : report.channels) {
    const std::string e2e = c.end_to_end.latency ? format_duration(*c.end_to_end.latency) : "unbounded";
    std::string details;
    if (c.end_to_end.reaction_time) details = "<= " + format_duration(*c.end_to_end.reaction_time) + " required";
    out << pad_column(c.name, 20) << pad_column(to_string(c.cls), 6) << pad_column(to_string(c.verdict), 10)
        << pad_column(e2e, 12) << details << "\n";
    for (const auto& reason : c.reasons) out << "    - " << reason << "\n";
  }
  std::size_t bound = 0;
  std::size_t degraded = 0;
  std::size_t rejected = 0;
  for (const auto& c : report.channels) {
    if (c.verdict == Verdict::bound) ++bound;
    if (c.verdict == Verdict::degraded) ++degraded;
    if (c.verdict == Verdict::rejected) ++rejected;
  }
  out << "\n" << bound << " bound, " << degraded << " degraded, " << rejected << " rejected\n";
  return out.str();
}

std::string render_channel_text(const ChannelReport& channel) {
  std::ostringstream out;
  out << channel.name << " (" << to_string(channel.cls) << "): " << to_string(channel.verdict) << "\n";
  for (const auto& reason : channel.reasons) out << "  - " << reason << "\n";
  for (const PathHop& hop : channel.upstream) {
    out << "  " << to_string(hop.role) << " " << hop.segment << " on gateway " << hop.gateway << "  "
        << (hop.latency ? format_duration(*hop.latency) : std::string("unbounded")) << "\n";
  }
  for (const auto& hop : channel.hops) {
    out << "  " << to_string(hop.role) << " " << hop.segment;
    if (hop.can) {
      out << "  id " << can_identifier_text(*hop.can) << " C " << format_duration(hop.can->transmission) << " x"
          << hop.can->frames_per_event;
    }
    if (hop.dds) out << "  topic " << hop.dds->topic << " type " << hop.dds->type;
    if (!hop.representation.empty()) out << "  as " << hop.representation;
    if (hop.security) {
      out << "  signed " << hop.security->scheme << " +" << hop.security->bytes << " B";
      if (hop.security->time) out << " " << format_duration(*hop.security->time);
    }
    out << "\n";
    for (const auto& check : hop.checks) {
      out << "    " << (check.ok ? "ok   " : "FAIL ") << pad_column(check.check, 14) << check_value_text(check) << " "
          << check.relation << " " << limit_text(check) << "\n";
    }
  }
  const EndToEnd& e2e = channel.end_to_end;
  out << "  end-to-end " << (e2e.latency ? format_duration(*e2e.latency) : std::string("unbounded"));
  if (!channel.upstream.empty()) {
    out << " (" << (e2e.upstream ? format_duration(*e2e.upstream) : std::string("unbounded"))
        << " before this gateway)";
  }
  if (e2e.reaction_time) out << ", reaction_time " << format_duration(*e2e.reaction_time);
  if (e2e.temp_validity) out << ", temp_validity " << format_duration(*e2e.temp_validity);
  out << (e2e.ok() ? "  ok" : "  FAIL") << "\n";
  return out.str();
}

}  // namespace cosmic

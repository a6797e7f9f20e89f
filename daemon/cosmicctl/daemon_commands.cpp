// cosmicctl commands that talk to a running cosmicd over its control socket.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "bind_output.hpp"
#include "commands.hpp"
#include "control_client.hpp"
#include "fmu_output.hpp"
#include "cosmic/report.hpp"
#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;
using cosmic::format_percent;
using cosmic::pad_column;

void print_status(const Json& r) {
  const Json& g = r["gateway"];
  std::cout << text(g["name"]) << " (id " << text(g["id"]) << "), up " << static_cast<long>(g["uptime_s"].get<double>())
            << " s\n"
            << "segments: " << r["segments"]["up"] << "/" << r["segments"]["total"] << " up\n"
            << "channels: " << r["channels"]["bound"] << " bound, " << r["channels"]["degraded"] << " degraded, "
            << r["channels"].value("failed", 0) << " failed, " << r["channels"].value("violated", 0)
            << " violated at run time\n"
            << "router:   " << r["router"]["queued"] << " queued, " << r["router"]["progress"] << " events handled\n";
}

void print_segments(const Json& r) {
  std::cout << pad_column("SEGMENT", 14) << pad_column("TYPE", 5) << pad_column("HEALTH", 9) << pad_column("UTIL", 7)
            << pad_column("LIMIT", 7) << pad_column("CHANNELS", 9) << pad_column("RX", 9) << pad_column("TX", 9)
            << pad_column("ERRORS", 7) << pad_column("OVERFLOW", 9) << "DETAIL\n";
  for (const auto& s : r["segments"]) {
    const Json& a = s["adapter"];
    std::cout << pad_column(text(s["name"]), 14) << pad_column(text(s["type"]), 5) << pad_column(text(s["health"]), 9)
              << pad_column(format_percent(s["utilization"].get<double>()), 7)
              << pad_column(format_percent(s["max_utilization"].get<double>()), 7) << pad_column(text(s["channels"]), 9)
              << pad_column(text(a["received"]), 9) << pad_column(text(a["sent"]), 9)
              << pad_column(
                     std::to_string(a["receive_errors"].get<std::uint64_t>() + a["send_errors"].get<std::uint64_t>()),
                     7)
              << pad_column(text(a["overflow_drops"]), 9) << text(s["detail"]) << "\n";
  }
  // CAN frames no binding and no background declaration explains: admission did not count them.
  for (const auto& s : r["segments"]) {
    if (!s.contains("unexplained") || (s["unexplained"].empty() && s.value("unexplained_others", 0) == 0)) continue;
    std::cout << "\n"
              << text(s["name"]) << ": unexplained frames (not in admission's analysis; declare them as background):\n";
    for (const auto& f : s["unexplained"]) {
      char rate[32];
      std::snprintf(rate, sizeof rate, "%.1f Hz", f["rate_hz"].get<double>());
      std::cout << "  " << pad_column(text(f["id"]), 12) << pad_column(rate, 12) << text(f["frames"]) << " frames\n";
    }
    if (s.value("unexplained_others", 0) > 0)
      std::cout << "  (and " << text(s["unexplained_others"]) << " frames of further identifiers)\n";
  }
  // LCM own_datagrams: drop: what the host's UDP InErrors counts of cosmicd's own sends.
  bool first_note = true;
  for (const auto& s : r["segments"]) {
    const Json& own = s["adapter"].value("own_datagrams_dropped", Json());
    if (!own.is_number_unsigned() || own.get<std::uint64_t>() == 0) continue;
    if (std::exchange(first_note, false)) std::cout << "\n";
    std::cout << text(s["name"]) << ": " << text(own)
              << " own datagrams dropped by its receive filter (each also counted in the host's UDP InErrors; "
                 "own_datagrams: cut avoids it)\n";
  }
  // Authenticated segments: what was refused, by kind (LCM: messages; DDS: participants).
  for (const auto& s : r["segments"]) {
    const Json& refused = s["adapter"].value("unauthenticated", Json());
    if (!refused.is_number_unsigned()) continue;
    if (std::exchange(first_note, false)) std::cout << "\n";
    if (text(s["type"]) == "dds") {
      const std::string last = s["adapter"].value("last_unauthenticated", "");
      std::cout << text(s["name"]) << ": secure; refused " << text(refused) << " unauthenticated participants"
                << (last.empty() ? std::string() : " (last " + last + ")") << "\n";
      continue;
    }
    std::cout << text(s["name"]) << ": authenticated; dropped " << text(refused) << " unauthenticated, "
              << text(s["adapter"].value("replayed", Json(0))) << " replayed\n";
  }
}

void print_peers(const Json& r) {
  const Json& f = r["federation"];
  if (!f["enabled"].get<bool>()) {
    const std::string error = f.value("error", "");
    std::cout << "federation: off" << (error.empty() ? std::string(" (gateway.federation is not set)") : ": " + error)
              << "\n";
    return;
  }
  std::cout << "federation over segment " << text(f["segment"]) << ", lease " << f["lease_s"].get<double>() << "s\n";
  std::cout << pad_column("GATEWAY", 16) << pad_column("ID", 18) << pad_column("STATE", 7) << pad_column("SUBJECT", 24)
            << pad_column("ANNOUNCED", 11) << pad_column("CHANNELS", 9) << "SEGMENTS\n";
  for (const auto& p : r["peers"]) {
    std::string segments;
    for (const auto& s : p.value("segments", Json::array())) {
      const std::string network = s.value("network", "");
      segments += (segments.empty() ? "" : ", ") + text(s["name"]) + (network.empty() ? "" : " [" + network + "]") +
                  " " + format_percent(s["load"].get<double>());
    }
    // The subject its authentication proved; "-" on a federation segment without security.
    const Json& subject = p.value("subject", Json());
    const std::string subject_text = subject.is_string() && !subject.get<std::string>().empty() ? text(subject) : "-";
    std::cout << pad_column(text(p["name"]), 16) << pad_column(text(p["id"]), 18) << pad_column(text(p["state"]), 7)
              << pad_column(subject_text, 24) << pad_column(age_text(p["last_heard_s"].get<double>()), 11)
              << pad_column(text(p["channels"]), 9) << segments << "\n";
  }
  const Json& c = r["counters"];
  if (c["refused"].get<std::uint64_t>() > 0 || c["dropped"].get<std::uint64_t>() > 0) {
    std::cout << "refused " << c["refused"] << ", dropped " << c["dropped"]
              << "; last refusal: " << text(c["last_refusal"]) << "\n";
  }
}

std::string drops_text(const Json& dropped) {
  std::string out;
  for (const auto& [reason, count] : dropped.items()) {
    if (count.get<std::uint64_t>() == 0) continue;
    out += (out.empty() ? "" : " ") + reason + "=" + count.dump();
  }
  return out.empty() ? "-" : out;
}

// The DROPPED column: the gateway's drops on the hop, then the events a protected hop's end-to-end
// counter shows missing before they reached it (not drops of this gateway, so named apart).
std::string hop_losses_text(const Json& segment) {
  std::string out = drops_text(segment["dropped"]);
  const std::uint64_t omitted = segment.value("omitted", std::uint64_t{0});
  if (omitted == 0) return out;
  return (out == "-" ? "" : out + " ") + "omitted=" + std::to_string(omitted) + " (" +
         std::to_string(segment.value("omission_excess", std::uint64_t{0})) + " gaps beyond omission_degree)";
}

void print_channels(const Json& r) {
  std::cout << pad_column("CHANNEL", 16) << pad_column("CLASS", 6) << pad_column("VERDICT", 9)
            << pad_column("RUNTIME", 9) << pad_column("ETAG", 6) << pad_column("SEGMENT", 12) << pad_column("ROLE", 4)
            << pad_column("RX", 9) << pad_column("TX", 9) << pad_column("RESIDENCE p50/p99", 19) << "DROPPED\n";
  for (const auto& c : r["channels"]) {
    bool first = true;
    const std::string residence = seconds_as_micros(c["residence"]["p50_s"].get<double>()) + "/" +
                                  seconds_as_micros(c["residence"]["p99_s"].get<double>());
    const std::string runtime = c.value("runtime_state", "bound") == "violated" ? "VIOLATED" : "ok";
    for (const auto& s : c["segments"]) {
      std::cout << pad_column(first ? text(c["name"]) : "", 16) << pad_column(first ? text(c["class"]) : "", 6)
                << pad_column(first ? text(c["verdict"]) : "", 9) << pad_column(first ? runtime : "", 9)
                << pad_column(first && c.contains("etag") ? text(c["etag"]) : "", 6)
                << pad_column(text(s["segment"]), 12) << pad_column(s["role"] == "publisher" ? "P" : "S", 4)
                << pad_column(text(s["rx"]), 9) << pad_column(text(s["tx"]), 9)
                << pad_column(first ? residence : "", 19) << hop_losses_text(s) << "\n";
      first = false;
    }
    for (const auto& reason : c["reasons"]) std::cout << "    - " << text(reason) << "\n";
    if (c.contains("mismatches")) {
      for (const auto& mismatch : c["mismatches"]) std::cout << "    ! QoS mismatch: " << text(mismatch) << "\n";
    }
  }
}

// Admission's prediction next to what the gateway measured, per egress hop.
void print_runtime(const Json& c) {
  std::cout << "\nruntime: " << c.value("runtime_state", "bound") << " (" << c.value("violations", 0)
            << " violation episodes), residence bound " << seconds_as_micros(c["residence"]["bound_s"].get<double>());
  if (c.contains("predicted_end_to_end_s"))
    std::cout << ", end-to-end predicted " << seconds_as_micros(c["predicted_end_to_end_s"].get<double>());
  if (c.contains("reaction_time_s"))
    std::cout << " <= reaction_time " << seconds_as_micros(c["reaction_time_s"].get<double>());
  std::cout << "\n";
  for (const auto& s : c["segments"]) {
    if (!s.contains("runtime")) continue;
    const Json& h = s["runtime"];
    std::cout << "  to " << pad_column(text(s["segment"]), 12) << "predicted hop "
              << pad_column(h["predicted_latency_s"].is_null()
                                ? "unbounded"
                                : seconds_as_micros(h["predicted_latency_s"].get<double>()),
                            10)
              << "measured residence p50 " << seconds_as_micros(h["residence_p50_s"].get<double>()) << " p99 "
              << seconds_as_micros(h["residence_p99_s"].get<double>()) << " p99.9 "
              << seconds_as_micros(h["residence_p999_s"].get<double>()) << " max "
              << seconds_as_micros(h["residence_max_s"].get<double>()) << "  misses: residence " << h["residence_miss"]
              << ", deadline " << h["deadline_miss"] << "\n";
  }
}

void print_channel(const Json& r) {
  const Json& c = r["channel"];
  print_channels(Json{{"channels", Json::array({c})}});
  // The contents' fields (a channel without a type carries opaque bytes).
  if (c.contains("type") && c["type"].is_string()) {
    std::cout << "\ncontents: " << text(c["type"]) << "\n";
    for (const auto& hop : c["segments"]) {
      if (hop.contains("representation") && hop["representation"].is_string())
        std::cout << "  on " << text(hop["segment"]) << ": " << text(hop["representation"]) << "\n";
    }
  }
  print_runtime(c);
  if (c.contains("fmus")) print_channel_fmus(c["fmus"]);
  std::cout << "\nadmission:\n";
  // A channel whose events come through other gateways (federation): their hops first.
  if (c["admission"].contains("upstream")) {
    const Json& e2e = c["admission"]["end_to_end"];
    std::cout << "  path over gateways: "
              << (e2e["upstream_s"].is_null() ? std::string("unbounded")
                                              : seconds_as_micros(e2e["upstream_s"].get<double>()))
              << " before this one, "
              << (e2e["local_s"].is_null() ? std::string("unbounded") : seconds_as_micros(e2e["local_s"].get<double>()))
              << " here\n";
    for (const auto& hop : c["admission"]["upstream"]) {
      std::cout << "  " << text(hop["role"]) << " " << text(hop["segment"]) << " on gateway " << text(hop["gateway"])
                << "  "
                << (hop["latency_s"].is_null() ? std::string("unbounded")
                                               : seconds_as_micros(hop["latency_s"].get<double>()))
                << "\n";
    }
  }
  for (const auto& hop : c["admission"]["hops"]) {
    std::cout << "  " << text(hop["role"]) << " " << text(hop["segment"]);
    if (hop.contains("can")) {
      const Json& can = hop["can"];
      cosmic::CanHopPlan plan;
      plan.can_id = can["can_id"].get<std::uint32_t>();
      plan.profile =
          can.value("layout", "cosmic") == "famouso" ? cosmic::CanProfile::famouso : cosmic::CanProfile::cosmic;
      plan.native = can.value("layout", "cosmic") == "native";
      plan.extended = can.value("extended", true);
      std::cout << "  can_id " << cosmic::can_identifier_text(plan);
    }
    if (hop.contains("dds"))
      std::cout << "  topic " << text(hop["dds"]["topic"]) << " type " << text(hop["dds"]["type"]);
    if (hop.contains("security")) {
      const Json& security = hop["security"];
      std::cout << "  signed " << text(security["scheme"]) << " +" << text(security["bytes"]) << " B";
      if (security["time_s"].is_number()) std::cout << " " << seconds_as_micros(security["time_s"].get<double>());
    }
    std::cout << "\n";
    for (const auto& check : hop["checks"]) {
      std::cout << "    " << (check["ok"].get<bool>() ? "ok   " : "FAIL ") << pad_column(text(check["check"]), 14)
                << text(check["value"]) << " " << text(check["relation"]) << " " << text(check["limit"]) << " "
                << text(check["unit"]) << "\n";
    }
  }
}

}  // namespace

std::vector<CommandRunner> add_daemon_commands(CLI::App& app, const GlobalOptions& options) {
  std::vector<CommandRunner> runners;
  auto simple = [&](const char* name, const char* help, auto print) {
    auto* command = app.add_subcommand(name, help);
    runners.push_back(add_request_command(
        app, options, command,
        [name](Json& req) {
          req = {{"command", name}};
          return kExitOk;
        },
        print));
  };
  simple("status", "Show the gateway's state in one screen", print_status);
  simple("segments", "List segments with health, load and counters", print_segments);
  simple("channels", "List channels with verdict, counters and drops by reason", print_channels);
  simple("peers", "List the other gateways of the federation as this one sees them", print_peers);
  simple("fmus", "List the configuration's FMUs with their runners' last reports (step times, late steps)", print_fmus);
  simple("reload", "Re-read the daemon's configuration file (validated before it is swapped in)", [](const Json& r) {
    std::cout << "reloaded\n";
    print_verdicts(r["channels"]);
  });

  auto* channel = app.add_subcommand("channel", "Show one channel with its admission numbers");
  auto channel_name = std::make_shared<std::string>();
  channel->add_option("NAME", *channel_name, "Channel name")->required();
  runners.push_back(add_request_command(
      app, options, channel,
      [channel_name](Json& req) {
        if (!is_utf8("channel name", *channel_name)) return kExitUsage;
        req = {{"command", "channel"}, {"name", *channel_name}};
        return kExitOk;
      },
      print_channel));

  auto* unbind = app.add_subcommand("unbind", "Unbind a channel and free its reservations");
  auto unbind_name = std::make_shared<std::string>();
  unbind->add_option("NAME", *unbind_name, "Channel name")->required();
  runners.push_back(add_request_command(
      app, options, unbind,
      [unbind_name](Json& req) {
        if (!is_utf8("channel name", *unbind_name)) return kExitUsage;
        req = {{"command", "unbind"}, {"name", *unbind_name}};
        return kExitOk;
      },
      [](const Json& r) { std::cout << "unbound " << text(r["unbound"]) << "\n"; }));

  auto* bind = app.add_subcommand("bind", "Bind channel definitions from a YAML file (admission decides)");
  auto bind_file = std::make_shared<std::string>();
  auto replace = std::make_shared<bool>(false);
  auto match_timeout = std::make_shared<std::string>();
  bind->add_option("FILE", *bind_file, "YAML with channel definitions")->required();
  auto* replace_flag = bind->add_flag(
      "--replace", *replace,
      "Replace the definitions of bound channels of the same names in one step (admission on the new whole "
      "set; rejected: nothing changes; subscribers that stay keep receiving). Made before break: new "
      "publishers are opened first and the old ones feed the channel until they have matched");
  bind->add_option("--match-timeout", *match_timeout,
                   "With --replace: how long the switch waits for new publishers to match a writer (DDS) before it "
                   "switches anyway, e.g. 500ms, 10s (default 5s, at most 60s)")
      ->needs(replace_flag);
  runners.push_back(add_request_command(
      app, options, bind,
      [bind_file, replace, match_timeout](Json& req) {
        std::ifstream in(*bind_file);
        if (!in) {
          std::cerr << "cosmicctl: cannot read " << *bind_file << "\n";
          return kExitConfigError;
        }
        std::stringstream content;
        content << in.rdbuf();
        if (!is_utf8("file name " + *bind_file, *bind_file)) return kExitUsage;
        if (!is_utf8(*bind_file, content.str())) return kExitConfigError;
        req = {{"command", *replace ? "replace" : "bind"}, {"yaml", content.str()}, {"file", *bind_file}};
        if (!match_timeout->empty()) {
          const auto timeout = cosmic::parse_duration(*match_timeout);
          if (!timeout.value || *timeout.value > std::chrono::seconds(60)) {
            std::cerr << "cosmicctl: --match-timeout: '" << *match_timeout
                      << "' is not a duration from 0 to 60s (e.g. 500ms, 10s)\n";
            return kExitUsage;
          }
          req["match_timeout_s"] = std::chrono::duration<double>(*timeout.value).count();
        }
        return kExitOk;
      },
      [](const Json& r) {
        print_verdicts(r["channels"]);
        if (r.contains("replaced")) print_replaced(r["replaced"]);
        if (r.contains("switch_over")) print_switch_over(r["switch_over"]);
      }));
  return runners;
}

}  // namespace cosmicctl

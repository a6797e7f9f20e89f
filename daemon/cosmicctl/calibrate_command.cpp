// `cosmicctl calibrate [FILE]`: measures this machine's residence (the gateway's forwarding plane
// under FILE's gateway.realtime) and says whether FILE's gateway.residence_bound covers its p99.9.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/report.hpp"
#include "cosmic/auth_timing.hpp"
#include "cosmic/dds_security_timing.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/residence_calibration.hpp"

namespace cosmicctl {
namespace {

struct CalibrateArguments {
  std::string file;
  double seconds = 2;
  double rate_hz = 1000;
  std::size_t dds_samples = 4000;
};

double micros(cosmic::Nanos value) { return static_cast<double>(value.count()) / 1e3; }

nlohmann::json to_json(const cosmic::CalibrationResult& result) {
  nlohmann::json phases = nlohmann::json::array();
  for (const auto& p : result.phases) {
    phases.push_back({{"phase", p.name},
                      {"hrt_events", p.hrt_events},
                      {"hrt_sent", p.hrt_sent},
                      {"residence_p50_us", micros(p.p50)},
                      {"residence_p99_us", micros(p.p99)},
                      {"residence_p999_us", micros(p.p999)},
                      {"residence_max_us", micros(p.max)},
                      {"residence_miss", p.residence_miss},
                      {"flood_offered", p.flood_offered},
                      {"flood_sent", p.flood_sent},
                      {"flood_queue_full", p.flood_queue_full}});
  }
  return {{"phases", phases},
          {"residence_bound_us", micros(result.residence_bound)},
          {"worst_p999_us", micros(result.worst_p999)},
          {"bound_covers_p999", result.bound_covers_p999()},
          {"thread_problems", result.thread_problems}};
}

void render_text(const cosmic::CalibrationResult& result, std::ostream& out) {
  char line[200];
  std::snprintf(line, sizeof line, "%-10s %9s %10s %10s %10s %10s %10s\n", "phase", "hrt", "p50", "p99", "p99.9", "max",
                "miss");
  out << line;
  for (const auto& p : result.phases) {
    std::snprintf(line, sizeof line, "%-10s %9llu %10s %10s %10s %10s %10llu\n", p.name.c_str(),
                  static_cast<unsigned long long>(p.hrt_events), cosmic::format_duration(p.p50).c_str(),
                  cosmic::format_duration(p.p99).c_str(), cosmic::format_duration(p.p999).c_str(),
                  cosmic::format_duration(p.max).c_str(), static_cast<unsigned long long>(p.residence_miss));
    out << line;
    if (p.flood_offered) {
      out << "           NRT flood: " << p.flood_offered << " offered, " << p.flood_sent << " sent, "
          << p.flood_queue_full << " dropped as queue_full\n";
    }
  }
  for (const auto& problem : result.thread_problems) out << "realtime: could not get " << problem << "\n";
}

// One authenticated LCM segment's figure: its largest message, and what signing or checking it
// costs; a channel's SecOC hop on CAN: its largest frame's data, protected or verified; or a secure
// DDS segment: what its governance's protection adds to a hop of its largest sample.
struct SegmentAuthTiming {
  std::string segment;
  std::string channel;                      // a SecOC hop's; empty for a segment's
  std::string scheme;                       // what was timed
  std::optional<cosmic::Nanos> configured;  // auth.cost, the hop's secoc.cost, or security.cost
  cosmic::AuthTiming timing;                // for DDS: `added` of the two runs below
  std::optional<cosmic::DdsSecurityTiming> dds{};
  bool covered() const { return configured && *configured >= timing.p999; }
};

// The largest payload of the channels with a hop on `segment`.
std::uint64_t largest_payload_on(const cosmic::Config& config, const std::string& segment) {
  std::uint64_t largest = 0;
  for (const auto& channel : config.channels) {
    const bool here =
        std::find(channel.publishers.begin(), channel.publishers.end(), segment) != channel.publishers.end() ||
        std::find(channel.subscribers.begin(), channel.subscribers.end(), segment) != channel.subscribers.end();
    if (here) largest = std::max(largest, channel.payload_on(segment));
  }
  return largest;
}

// The authenticated segments of `config`, each timed with its largest envelope (the channels' hops there).
std::vector<SegmentAuthTiming> time_authentication(const cosmic::Config& config) {
  constexpr std::size_t kRuns = 20000;
  std::vector<SegmentAuthTiming> out;
  for (const auto& segment : config.segments) {
    if (segment.type != cosmic::SegmentType::lcm || !segment.lcm.auth) continue;
    const std::size_t message =
        static_cast<std::size_t>(largest_payload_on(config, segment.name)) + cosmic::kLcmEnvelopeHeaderSize;
    out.push_back(
        {segment.name, "", "HMAC-SHA256 trailer", segment.lcm.auth->cost, cosmic::time_lcm_auth(message, kRuns)});
  }
  for (const auto& channel : config.channels) {
    for (const auto& secoc : channel.secoc) {
      const auto data = static_cast<std::size_t>(channel.payload_on(secoc.segment));
      out.push_back({secoc.segment, channel.name, "SecOC AES-128-CMAC", secoc.cost,
                     cosmic::time_secoc(data, secoc.mac_bits, secoc.freshness_bits, kRuns)});
    }
  }
  return out;
}

// A domain none of `config`'s DDS segments uses, for the calibration's own participants.
std::uint32_t unused_dds_domain(const cosmic::Config& config) {
  std::uint32_t domain = 232;  // the highest the default port mapping allows
  const auto used = [&](std::uint32_t d) {
    return std::any_of(config.segments.begin(), config.segments.end(), [&](const cosmic::SegmentSpec& s) {
      return s.type == cosmic::SegmentType::dds && s.dds.domain == d;
    });
  };
  while (domain > 0 && used(domain)) --domain;
  return domain;
}

// Each secure DDS segment timed with its largest sample and its governance's strongest protection.
cosmic::Result<std::vector<SegmentAuthTiming>> time_dds_security_hops(const cosmic::Config& config,
                                                                      std::size_t samples) {
  std::vector<SegmentAuthTiming> out;
  for (const auto& segment : config.segments) {
    if (segment.type != cosmic::SegmentType::dds || !segment.dds.security) continue;
    const cosmic::DdsSecuritySpec& security = *segment.dds.security;
    std::ifstream file(security.governance);
    std::ostringstream governance;
    governance << file.rdbuf();
    const auto protection = cosmic::governance_protection(governance.str());
    if (!protection)
      return cosmic::Error{"segment " + segment.name + ": " + security.governance + " " + protection.error().text};
    cosmic::DdsSecurityTimingRequest request;
    request.protection = protection.value();
    request.payload_bytes = static_cast<std::size_t>(largest_payload_on(config, segment.name));
    request.domain = unused_dds_domain(config);
    request.samples = samples;
    auto timing = cosmic::time_dds_security(request);
    if (!timing) return cosmic::Error{"segment " + segment.name + ": " + timing.error().text};
    const std::string scheme = std::string("DDS Security ") + cosmic::to_string(request.protection);
    out.push_back({segment.name, "", scheme, security.cost, timing.value().added, timing.value()});
  }
  return out;
}

std::string hop_name(const SegmentAuthTiming& t) { return t.channel.empty() ? t.segment : t.channel + "@" + t.segment; }

void render_auth_text(const std::vector<SegmentAuthTiming>& timings, std::ostream& out) {
  if (timings.empty()) return;
  char line[200];
  std::snprintf(line, sizeof line, "\n%-16s %9s %10s %10s %10s %10s  %s\n", "authentication", "message", "p50", "p99",
                "p99.9", "max", "cost (auth.cost, secoc.cost, security.cost)");
  out << line;
  for (const auto& t : timings) {
    std::snprintf(line, sizeof line, "%-16s %7zu B %10s %10s %10s %10s  %s\n", hop_name(t).c_str(),
                  t.timing.message_bytes, cosmic::format_duration(t.timing.p50).c_str(),
                  cosmic::format_duration(t.timing.p99).c_str(), cosmic::format_duration(t.timing.p999).c_str(),
                  cosmic::format_duration(t.timing.max).c_str(),
                  !t.configured ? "not set: admission does not count it"
                  : t.covered() ? ("covers p99.9 (" + cosmic::format_duration(*t.configured) + ")").c_str()
                                : ("BELOW p99.9 (" + cosmic::format_duration(*t.configured) + ")").c_str());
    out << line;
    if (t.dds) {
      const cosmic::DdsSecurityTiming& d = *t.dds;
      out << "  " << t.scheme << ": one-way p50 " << cosmic::format_duration(d.plain.p50) << " plain, "
          << cosmic::format_duration(d.protected_.p50) << " protected; p99.9 " << cosmic::format_duration(d.plain.p999)
          << ", " << cosmic::format_duration(d.protected_.p999) << "; CPU " << static_cast<long>(d.plain_cpu_us + 0.5)
          << " us, " << static_cast<long>(d.protected_cpu_us + 0.5) << " us per sample; " << d.lost << " lost\n";
    }
  }
}

nlohmann::json timing_json(const cosmic::AuthTiming& t) {
  return {{"runs", t.runs},
          {"p50_us", micros(t.p50)},
          {"p99_us", micros(t.p99)},
          {"p999_us", micros(t.p999)},
          {"max_us", micros(t.max)}};
}

nlohmann::json auth_json(const std::vector<SegmentAuthTiming>& timings) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : timings) {
    out.push_back({{"segment", t.segment},
                   {"channel", t.channel.empty() ? nlohmann::json() : nlohmann::json(t.channel)},
                   {"scheme", t.scheme},
                   {"message_bytes", t.timing.message_bytes},
                   {"runs", t.timing.runs},
                   {"p50_us", micros(t.timing.p50)},
                   {"p99_us", micros(t.timing.p99)},
                   {"p999_us", micros(t.timing.p999)},
                   {"max_us", micros(t.timing.max)},
                   {"configured_cost_us", t.configured ? nlohmann::json(micros(*t.configured)) : nlohmann::json()},
                   {"cost_covers_p999", t.covered()}});
    if (t.dds) {
      out.back()["plain"] = timing_json(t.dds->plain);
      out.back()["protected"] = timing_json(t.dds->protected_);
      out.back()["plain_cpu_us_per_sample"] = t.dds->plain_cpu_us;
      out.back()["protected_cpu_us_per_sample"] = t.dds->protected_cpu_us;
      out.back()["lost"] = t.dds->lost;
    }
  }
  return out;
}

}  // namespace

CommandRunner add_calibrate_command(CLI::App& app, const GlobalOptions& options) {
  auto* command = app.add_subcommand(
      "calibrate", "Measure this machine's residence p99.9 and compare it with gateway.residence_bound");
  auto args = std::make_shared<CalibrateArguments>();
  command->add_option("FILE", args->file, "Configuration whose gateway.realtime and residence_bound to use")
      ->check(CLI::ExistingFile);
  command->add_option("--seconds", args->seconds, "Duration of each phase (idle, NRT flood)")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 600.0));
  command->add_option("--rate", args->rate_hz, "HRT events per second")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100000.0));
  command->add_option("--dds-samples", args->dds_samples, "Samples per run timing a secure DDS segment's protection")
      ->capture_default_str()
      ->check(CLI::Range(100, 1000000));
  return [command, args, &options]() -> int {
    if (!command->parsed()) return -1;
    cosmic::GatewaySpec gateway;
    std::vector<SegmentAuthTiming> authentication;
    if (!args->file.empty()) {
      const auto loaded = cosmic::load_config_file(args->file);
      if (!loaded.ok()) {
        for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
        std::cerr << loaded.errors.size() << " error(s) in " << args->file << "\n";
        return kExitConfigError;
      }
      gateway = loaded.config.gateway;
      authentication = time_authentication(loaded.config);
      auto dds = time_dds_security_hops(loaded.config, args->dds_samples);
      if (!dds) {
        std::cerr << "error: DDS Security could not be timed: " << dds.error().text << "\n";
        return kExitRejected;
      }
      authentication.insert(authentication.end(), dds.value().begin(), dds.value().end());
    }
    cosmic::CalibrationOptions calibration;
    calibration.phase_duration = cosmic::Nanos(static_cast<std::int64_t>(args->seconds * 1e9));
    calibration.hrt_rate_hz = args->rate_hz;
    const auto result = cosmic::calibrate_residence(gateway, calibration);
    const bool costs_covered = std::all_of(authentication.begin(), authentication.end(),
                                           [](const SegmentAuthTiming& t) { return !t.configured || t.covered(); });
    if (options.json) {
      nlohmann::json json = to_json(result);
      json["authentication"] = auth_json(authentication);
      std::cout << json.dump(2) << "\n";
    } else {
      render_text(result, std::cout);
      std::cout << "residence_bound " << cosmic::format_duration(result.residence_bound)
                << (result.bound_covers_p999() ? " covers" : " is BELOW") << " this machine's residence p99.9 "
                << cosmic::format_duration(result.worst_p999) << "\n";
      render_auth_text(authentication, std::cout);
    }
    for (const auto& t : authentication) {
      if (t.configured && !t.covered())
        std::cerr << "warning: "
                  << (t.dds               ? "segment " + t.segment + ": security.cost "
                      : t.channel.empty() ? "segment " + t.segment + ": auth.cost "
                                          : "channel " + t.channel + " on " + t.segment + ": secoc.cost ")
                  << cosmic::format_duration(*t.configured) << " is below the p99.9 measured here ("
                  << cosmic::format_duration(t.timing.p999)
                  << "): raise it, or admission promises latencies this machine does not hold\n";
    }
    if (result.bound_covers_p999() && costs_covered) return kExitOk;
    if (result.bound_covers_p999()) return kExitRejected;
    std::cerr << "warning: gateway.residence_bound " << cosmic::format_duration(result.residence_bound)
              << " is below the residence p99.9 measured here (" << cosmic::format_duration(result.worst_p999)
              << "): HRT channels will be reported violated; raise residence_bound, configure gateway.realtime, "
                 "or give cosmicd a quieter machine\n";
    return kExitRejected;
  };
}

}  // namespace cosmicctl

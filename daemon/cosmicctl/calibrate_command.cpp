// `cosmicctl calibrate [FILE]`: measures this machine's residence (the gateway's forwarding plane
// under FILE's gateway.realtime) and says whether FILE's gateway.residence_bound covers its p99.9.
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/report.hpp"
#include "cosmic/residence_calibration.hpp"

namespace cosmicctl {
namespace {

struct CalibrateArguments {
  std::string file;
  double seconds = 2;
  double rate_hz = 1000;
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
  return [command, args, &options]() -> int {
    if (!command->parsed()) return -1;
    cosmic::GatewaySpec gateway;
    if (!args->file.empty()) {
      const auto loaded = cosmic::load_config_file(args->file);
      if (!loaded.ok()) {
        for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
        std::cerr << loaded.errors.size() << " error(s) in " << args->file << "\n";
        return kExitConfigError;
      }
      gateway = loaded.config.gateway;
    }
    cosmic::CalibrationOptions calibration;
    calibration.phase_duration = cosmic::Nanos(static_cast<std::int64_t>(args->seconds * 1e9));
    calibration.hrt_rate_hz = args->rate_hz;
    const auto result = cosmic::calibrate_residence(gateway, calibration);
    if (options.json) {
      std::cout << to_json(result).dump(2) << "\n";
    } else {
      render_text(result, std::cout);
      std::cout << "residence_bound " << cosmic::format_duration(result.residence_bound)
                << (result.bound_covers_p999() ? " covers" : " is BELOW") << " this machine's residence p99.9 "
                << cosmic::format_duration(result.worst_p999) << "\n";
    }
    if (result.bound_covers_p999()) return kExitOk;
    std::cerr << "warning: gateway.residence_bound " << cosmic::format_duration(result.residence_bound)
              << " is below the residence p99.9 measured here (" << cosmic::format_duration(result.worst_p999)
              << "): HRT channels will be reported violated; raise residence_bound, configure gateway.realtime, "
                 "or give cosmicd a quieter machine\n";
    return kExitRejected;
  };
}

}  // namespace cosmicctl

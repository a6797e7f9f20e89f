// cosmic-fmu: one co-simulation FMU of a gateway configuration's `fmus:` section run as a component
// on its segment (issue 38; docs/fmu.md, man page cosmic-fmu(1)).
//
// Exit codes: 0 stopped (signal or --steps reached); 1 the FMU failed (extract, load, initialize or
// a step: its own messages are logged); 2 the configuration has errors or no such FMU; 64 usage.
#include <pthread.h>
#include <signal.h>
#include <sys/mman.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cstdlib>

#include "cosmic/config_loader.hpp"
#include "cosmic/thread_policy.hpp"
#include "cosmic/units.hpp"
#include "cosmic/version.hpp"
#include "daemon_logger.hpp"
#include "fmu_runner.hpp"
#include "status_reporter.hpp"

namespace {

std::atomic<bool> g_stop{false};  // set by SIGINT / SIGTERM; the step loop looks at it between steps

void on_stop_signal(int) { g_stop.store(true); }

struct Arguments {
  std::string config;
  std::string name;
  std::string pace = "realtime";
  std::uint64_t steps = 0;
  std::string socket;
  bool no_report = false;
  std::string report_interval = "1s";
  std::string ready_timeout = "10s";
  std::string work_dir;
  std::string trace;
  int can_node = -1;
  int priority = 0;
  std::vector<int> cpus;
  std::string log_level = "info";
};

// The step thread's scheduling (--priority, --cpus), applied once everything else is started, so
// that only the step thread runs SCHED_FIFO (threads inherit their creator's class); with a
// priority the process's memory is locked as cosmicd locks it, so no page fault delays a step.
void apply_step_policy(const Arguments& args, cosmic::Logger& log) {
  if (args.priority == 0 && args.cpus.empty()) return;
  cosmic::ThreadPolicy policy{"fmu-step", args.priority, 0, args.cpus};
  for (const auto& why : cosmic::apply_thread_policy(policy))
    log.log(cosmic::LogLevel::warning, "the step thread runs without " + why);
  if (args.priority > 0 && ::mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    log.log(cosmic::LogLevel::warning, "memory not locked (mlockall: " + cosmic::errno_text(errno) + ")");
}

// A duration option's value, or a usage error naming the option.
cosmic::Nanos duration_option(const std::string& option, const std::string& text) {
  const auto parsed = cosmic::parse_duration(text);
  if (!parsed.value || parsed.value->count() <= 0)
    throw CLI::ValidationError(option, "'" + text + "' is not a positive duration (10ms, 1s, ...)");
  return *parsed.value;
}

// The FMU's default TxNode on a CAN segment: after the gateway's and the components' (as cosmicctl
// gen numbers components), by its place in `fmus:`.
unsigned default_can_node(const cosmic::Config& config, const cosmic::FmuSpec& spec) {
  const auto position = static_cast<unsigned>(&spec - config.fmus.data());
  return (config.gateway.can_node_id + 1 + static_cast<unsigned>(config.components.size()) + position) % 128;
}

int run(const Arguments& args, cosmic::Nanos report_interval, cosmic::Nanos ready_timeout) {
  cosmicd::DaemonLogger log(cosmicd::parse_log_level(args.log_level));
  const cosmic::ConfigResult loaded = cosmic::load_config_file(args.config);
  if (!loaded.errors.empty()) {
    for (const auto& e : loaded.errors) log.log(cosmic::LogLevel::error, e.to_string());
    return 2;
  }
  const cosmic::Config& config = loaded.config;
  const auto spec =
      std::find_if(config.fmus.begin(), config.fmus.end(), [&](const auto& f) { return f.name == args.name; });
  if (spec == config.fmus.end()) {
    std::string names;
    for (const auto& f : config.fmus) names += (names.empty() ? "" : ", ") + f.name;
    log.log(cosmic::LogLevel::error, args.config + ": no FMU named '" + args.name + "' in fmus: (" +
                                         (names.empty() ? "it has none" : "it has " + names) + ")");
    return 2;
  }
  cosmic_fmu::RunnerOptions options;
  options.paced = args.pace == "realtime";
  options.steps = args.steps;
  options.ready_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(ready_timeout);
  const char* runtime_directory = std::getenv("RUNTIME_DIRECTORY");
  options.work_parent = !args.work_dir.empty() ? args.work_dir : runtime_directory ? runtime_directory : "/tmp";
  options.trace_file = args.trace;
  options.can_node = args.can_node >= 0 ? static_cast<unsigned>(args.can_node) : default_can_node(config, *spec);

  const std::string socket = args.no_report ? "" : !args.socket.empty() ? args.socket : config.gateway.control_socket;
  auto runner = cosmic_fmu::FmuRunner::open(config, *spec, options, log);
  if (!runner) {
    log.log(cosmic::LogLevel::error, "fmu " + spec->name + " (" + spec->fmu + "): " + runner.error().text);
    cosmic_fmu::report_failure(socket, *spec, runner.error().text);
    return 1;
  }
  log.log(cosmic::LogLevel::info, "fmu " + spec->name + ": FMI " + spec->fmi_version + " model " +
                                      spec->model_identifier + " initialized on segment " + spec->segment + ", step " +
                                      cosmic::format_duration(spec->step) + (options.paced ? ", paced" : ", unpaced"));
  cosmic::Result<void> result = cosmic::Result<void>{};
  {
    cosmic_fmu::ReporterOptions reporting;
    reporting.socket = socket;
    reporting.interval = std::chrono::duration_cast<std::chrono::milliseconds>(report_interval);
    cosmic_fmu::StatusReporter reporter(*runner.value(), reporting, log);
    apply_step_policy(args, log);
    // SIGINT and SIGTERM come to this thread alone from now on (main() blocked them before any other
    // thread existed, and threads inherit the mask): its sleep until the next step ends at once.
    sigset_t stop_signals;
    ::sigemptyset(&stop_signals);
    ::sigaddset(&stop_signals, SIGINT);
    ::sigaddset(&stop_signals, SIGTERM);
    ::pthread_sigmask(SIG_UNBLOCK, &stop_signals, nullptr);
    result = runner.value()->run(g_stop);
    log.log(result ? cosmic::LogLevel::info : cosmic::LogLevel::error,
            "fmu " + spec->name + " " + cosmic_fmu::summary_line(spec->step, runner.value()->status()));
  }  // the reporter's last report says stopped or failed
  if (!result) {
    // The failure and the FMU's own messages (its last kMaxKeptLogLines), as the report carries them.
    log.log(cosmic::LogLevel::error, "fmu " + spec->name + " stopped: " + runner.value()->status().message);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cosmic-fmu: a co-simulation FMU of the gateway's configuration run as a component"};
  app.set_version_flag("--version", "cosmic-fmu " COSMIC_VERSION);
  Arguments args;
  app.add_option("-c,--config", args.config, "The gateway's configuration (its fmus: section names the FMU)")
      ->required();
  app.add_option("-n,--name", args.name, "The fmus: entry to run")->required();
  app.add_option("--pace", args.pace, "realtime: step k starts at k*step; free: as fast as it goes (against a replay)")
      ->check(CLI::IsMember({"realtime", "free"}))
      ->capture_default_str();
  app.add_option("--steps", args.steps, "Stop after this many steps (0: until SIGTERM/SIGINT)")->capture_default_str();
  app.add_option("-s,--socket", args.socket, "cosmicd's control socket for reports (default gateway.control_socket)");
  app.add_flag("--no-report", args.no_report, "Send no fmu_report to cosmicd");
  app.add_option("--report-interval", args.report_interval, "How often the status is reported")->capture_default_str();
  app.add_option("--ready-timeout", args.ready_timeout, "How long to wait for the output channels to be carried")
      ->capture_default_str();
  app.add_option("--work-dir", args.work_dir, "Where the FMU is extracted (default $RUNTIME_DIRECTORY or /tmp)");
  app.add_option("--trace", args.trace, "Write every step's inputs and outputs to this CSV file");
  app.add_option("--can-node", args.can_node, "TxNode on a CAN segment (0-127; default after the components')")
      ->check(CLI::Range(0, 127));
  app.add_option("--priority", args.priority, "SCHED_FIFO priority of the step thread (1-99; 0: time-shared)")
      ->check(CLI::Range(0, 99))
      ->capture_default_str();
  app.add_option("--cpus", args.cpus, "CPUs the step thread may run on (comma-separated; default any)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1023));
  app.add_option("-l,--log-level", args.log_level, "debug, info, notice, warning or error")
      ->check(CLI::IsMember({"debug", "info", "notice", "warning", "error"}))
      ->capture_default_str();
  cosmic::Nanos report_interval{}, ready_timeout{};
  try {
    app.parse(argc, argv);
    report_interval = duration_option("--report-interval", args.report_interval);
    ready_timeout = duration_option("--ready-timeout", args.ready_timeout);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 64;
  }
  ::pthread_setname_np(::pthread_self(), "fmu-step");
  struct sigaction stop {};
  stop.sa_handler = on_stop_signal;  // no SA_RESTART: the step loop's sleep returns at once
  ::sigaction(SIGINT, &stop, nullptr);
  ::sigaction(SIGTERM, &stop, nullptr);
  // Blocked until the step thread steps (run() unblocks them there): every thread started before
  // (the client's, the reporter) inherits the block, so none of them takes a stop signal that the
  // step thread's sleep would then not see. One that comes earlier waits, and stops the first step.
  sigset_t stop_signals;
  ::sigemptyset(&stop_signals);
  ::sigaddset(&stop_signals, SIGINT);
  ::sigaddset(&stop_signals, SIGTERM);
  ::pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  return run(args, report_interval, ready_timeout);
}

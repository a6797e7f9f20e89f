#include "status_reporter.hpp"

#include <pthread.h>
#include <systemd/sd-daemon.h>

#include <cstdio>

#include "control_client.hpp"
#include "cosmic/units.hpp"

namespace cosmic_fmu {
namespace {

std::string millis(std::chrono::nanoseconds d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g ms", static_cast<double>(d.count()) / 1e6);
  return text;
}

}  // namespace

nlohmann::json report_request(const std::string& name, std::chrono::nanoseconds step, const RunnerStatus& s) {
  nlohmann::json skipped = nlohmann::json::object();
  for (const auto& in : s.inputs) skipped[in.channel] = in.skipped;
  return {{"command", "fmu_report"},
          {"name", name},
          {"state", to_string(s.state)},
          {"step_ns", step.count()},
          {"steps", s.timing.steps},
          {"late_steps", s.timing.late_steps},
          {"worst_step_ns", s.timing.worst.count()},
          {"p99_step_ns", s.timing.p99.count()},
          {"skipped", skipped},
          {"message", s.message}};
}

std::string summary_line(std::chrono::nanoseconds step, const RunnerStatus& s) {
  std::string line = std::string(to_string(s.state)) + ": " + std::to_string(s.timing.steps) + " steps of " +
                     cosmic::format_duration(step) + ", " + std::to_string(s.timing.late_steps) +
                     " late, step time p50 " + millis(s.timing.p50) + " p99 " + millis(s.timing.p99) + " worst " +
                     millis(s.timing.worst);
  std::uint64_t skipped = 0, undecodable = 0, clipped = 0;
  for (const auto& in : s.inputs) {
    skipped += in.skipped;
    undecodable += in.decode_errors;
  }
  for (const auto& out : s.outputs) clipped += out.clipped;
  line += "; input events skipped " + std::to_string(skipped);
  if (undecodable != 0) line += ", undecodable " + std::to_string(undecodable);
  if (clipped != 0) line += "; output values clipped " + std::to_string(clipped);
  if (s.publish_errors != 0) line += "; publish errors " + std::to_string(s.publish_errors);
  return line;
}

StatusReporter::StatusReporter(const FmuRunner& runner, ReporterOptions options, cosmic::Logger& log)
    : runner_(runner), options_(std::move(options)), log_(log) {
  thread_ = std::thread([this] {
    ::pthread_setname_np(::pthread_self(), "fmu-report");
    loop();
  });
}

StatusReporter::~StatusReporter() {
  {
    cosmic::LockGuard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void StatusReporter::loop() {
  auto next_log = std::chrono::steady_clock::now() + options_.log_interval;
  cosmic::UniqueLock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    const RunnerStatus status = runner_.status();
    send(status);
    if (std::chrono::steady_clock::now() >= next_log && status.state == RunnerState::running) {
      log_.log(cosmic::LogLevel::info, summary_line(runner_.spec().step, status));
      next_log += options_.log_interval;
    }
    lock.lock();
    if (!stopping_) lock.wait_for(wake_, options_.interval);
  }
  lock.unlock();
  send(runner_.status());  // the last word: stopped or failed, with the final counters
}

void StatusReporter::send(const RunnerStatus& status) {
  const std::string line = summary_line(runner_.spec().step, status);
  // Nothing without NOTIFY_SOCKET. READY=1 once the FMU steps: extracted, initialized, joined.
  const bool ready = status.state != RunnerState::starting;
  ::sd_notifyf(0, "%sSTATUS=%s", ready && !ready_sent_ ? "READY=1\n" : "", line.c_str());
  ready_sent_ = ready_sent_ || ready;
  if (options_.socket.empty()) return;
  const auto answer =
      cosmicctl::request(options_.socket, report_request(runner_.spec().name, runner_.spec().step, status),
                         static_cast<int>(options_.interval.count()));
  std::string why;
  if (!answer.response) {
    why = answer.error;
  } else if (!answer.response->value("ok", false)) {
    const auto& error = (*answer.response)["error"];
    why = error.is_object() ? error.value("message", error.dump()) : answer.response->dump();
  }
  if (why.empty()) {
    warned_unreachable_ = false;
  } else if (!warned_unreachable_) {
    log_.log(cosmic::LogLevel::warning, "cannot report to cosmicd at " + options_.socket + ": " + why + " (retrying)");
    warned_unreachable_ = true;
  }
}

}  // namespace cosmic_fmu

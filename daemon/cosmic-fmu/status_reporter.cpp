#include "status_reporter.hpp"

#include <pthread.h>
#include <systemd/sd-daemon.h>

#include <cstdio>

#include "control_client.hpp"

namespace cosmic_fmu {
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
    const RunnerStatus status = runner_.status(/*take_window=*/true);
    send(status);
    if (std::chrono::steady_clock::now() >= next_log && status.state == RunnerState::running) {
      log_.log(cosmic::LogLevel::info, summary_line(runner_.spec().step, status));
      next_log += options_.log_interval;
    }
    lock.lock();
    if (!stopping_) lock.wait_for(wake_, options_.interval);
  }
  lock.unlock();
  send(runner_.status(/*take_window=*/true));  // the last word: stopped or failed, with the final counters
}

void report_failure(const std::string& socket, const cosmic::FmuSpec& spec, const std::string& message) {
  if (socket.empty()) return;
  RunnerStatus failed;
  failed.state = RunnerState::failed;
  failed.message = message;
  (void)cosmicctl::request(socket, report_request(spec.name, spec.step, failed), 1000);  // best effort, once
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

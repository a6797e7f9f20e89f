// cosmic-fmu's status (issue 38, docs/fmu.md "Timing"): every interval the runner's counters go to
// the gateway as a `fmu_report` control request (docs/control-protocol.md), to the service manager
// as STATUS= (when NOTIFY_SOCKET is set; READY=1 with the first report once the FMU steps), and now
// and then to the log.
//
// Owns one thread ("fmu-report"); never touches the FMU. The control socket is asked with a
// timeout, so a gateway that hangs delays only the next report, never a step.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cosmic/log.hpp"
#include "cosmic/mutex.hpp"
#include "fmu_runner.hpp"

namespace cosmic_fmu {

struct ReporterOptions {
  std::string socket;                        // cosmicd's control socket; empty: no reports
  std::chrono::milliseconds interval{1000};  // reports and STATUS=
  std::chrono::milliseconds log_interval{10'000};
};

// One `failed` report for an FMU that failed before it stepped (no StatusReporter exists yet).
void report_failure(const std::string& socket, const cosmic::FmuSpec& spec, const std::string& message);

class StatusReporter {
 public:
  StatusReporter(const FmuRunner& runner, ReporterOptions options, cosmic::Logger& log);
  // Stops the thread after one last report (destroy it once the runner stopped: the report says
  // stopped or failed, with the final counters).
  ~StatusReporter();
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

 private:
  void loop();
  void send(const RunnerStatus& status);

  const FmuRunner& runner_;
  ReporterOptions options_;
  cosmic::Logger& log_;
  bool warned_unreachable_ = false;  // the reporter thread's
  bool ready_sent_ = false;          // the reporter thread's: READY=1 went to the service manager
  cosmic::Mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ COSMIC_GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace cosmic_fmu

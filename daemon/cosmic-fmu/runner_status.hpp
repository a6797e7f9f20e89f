// What cosmic-fmu says about a run (its status line, STATUS=, the `fmu_report` request) and the
// plain values it is made from. Pure functions; any thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/fmu_stepper.hpp"
#include "step_timing.hpp"

namespace cosmic_fmu {

enum class RunnerState { starting, running, stopped, failed };
const char* to_string(RunnerState state);

struct RunnerStatus {
  RunnerState state = RunnerState::starting;
  StepTimingSnapshot timing;
  std::vector<cosmic::fmi::InputCounters> inputs;
  std::vector<cosmic::fmi::OutputCounters> outputs;
  std::uint64_t publish_errors = 0;
  std::string message;  // why it failed, with the FMU's last messages
};

// The longest `message` a report carries (the FMU's kept messages can be longer; the log has them all).
inline constexpr std::size_t kMaxReportedMessage = 8192;

// The `fmu_report` request for `status` (docs/control-protocol.md): worst_step_ns is the worst step
// since the previous report (StepTimingSnapshot::worst_recent), the message cut after a whole line
// at kMaxReportedMessage.
nlohmann::json report_request(const std::string& name, std::chrono::nanoseconds step, const RunnerStatus& status);
// The one-line summary for STATUS= and the log: "running: 1234 steps of 10 ms, 0 late, step time p50 ...".
std::string summary_line(std::chrono::nanoseconds step, const RunnerStatus& status);

}  // namespace cosmic_fmu

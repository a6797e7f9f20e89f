#include "runner_status.hpp"

#include <cstdio>

#include "cosmic/units.hpp"

namespace cosmic_fmu {

const char* to_string(RunnerState state) {
  switch (state) {
    case RunnerState::starting:
      return "starting";
    case RunnerState::running:
      return "running";
    case RunnerState::stopped:
      return "stopped";
    case RunnerState::failed:
      return "failed";
  }
  return "unknown";
}

namespace {

std::string millis(std::chrono::nanoseconds d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g ms", static_cast<double>(d.count()) / 1e6);
  return text;
}

// At most kMaxReportedMessage bytes, cut after a whole line (each line is whole UTF-8).
std::string bounded_message(const std::string& message) {
  if (message.size() <= kMaxReportedMessage) return message;
  const std::size_t end = message.rfind('\n', kMaxReportedMessage);
  return message.substr(0, end == std::string::npos ? 0 : end + 1) + "...";
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
          {"worst_step_ns", s.timing.worst_recent.count()},  // since the previous report
          {"p99_step_ns", s.timing.p99.count()},
          {"skipped", skipped},
          {"message", bounded_message(s.message)}};
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

}  // namespace cosmic_fmu

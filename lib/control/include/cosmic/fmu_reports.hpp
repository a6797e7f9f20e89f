// What the runners of the configuration's FMUs (cosmic-fmu, docs/fmu.md) last reported through the
// control command `fmu_report` (docs/control-protocol.md), and what the gateway shows of it: the
// `fmus` answer, the FMU part of a channel's answer, and the output channels of an FMU whose measured
// worst step overran its step (the gateway judges them violated, Gateway::set_reported_violations).
// The FMUs themselves are the running configuration's `fmus:` (Config::fmus), passed in by the caller;
// a report of an FMU not among them is refused. Control thread only.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmic {

// One runner report as it came: the runner's counters since it started.
struct FmuReport {
  std::string state;                // starting, running, stopped, failed
  std::uint64_t step_ns = 0;        // the runner's communication step (> 0)
  std::uint64_t steps = 0;          // steps done
  std::uint64_t late_steps = 0;     // steps that ended after their deadline
  std::uint64_t worst_step_ns = 0;  // the longest step (doStep with its inputs and outputs)
  std::uint64_t p99_step_ns = 0;
  std::map<std::string, std::uint64_t> skipped;  // input -> events a step replaced before taking them
  std::string message;                           // the FMU's last log lines when failed; may be empty
  std::chrono::steady_clock::time_point received{};
};

class FmuReports {
 public:
  using Json = nlohmann::json;
  using Clock = std::chrono::steady_clock;
  // A report older than this is shown stale and no longer flags its FMU's channels: the runner has
  // stopped reporting (it reports about once a second).
  static constexpr std::chrono::seconds kStaleAfter{3};

  // `request` is an fmu_report of an FMU of `fmus`: kept as that FMU's latest report, received
  // `now`, and the answer {"ok":true}. Otherwise a failure answer (unknown FMU, a field missing, of
  // the wrong type or negative, an unknown state) and nothing is kept.
  Json accept(const Json& request, const std::vector<FmuSpec>& fmus, Clock::time_point now);
  // Drops the reports of FMUs `fmus` no longer has (a reload).
  void keep_configured(const std::vector<FmuSpec>& fmus);
  const FmuReport* find(const std::string& fmu) const;

  // The `fmus` answer: every FMU of `fmus` with its configuration, its latest report (null when it
  // never reported) and its age, and why it flags its channels (null when it does not).
  Json fmus_answer(const std::vector<FmuSpec>& fmus, Clock::time_point now) const;
  // A channel answer's "fmus": each FMU of `fmus` publishing (outputs) or subscribing (inputs)
  // `channel`, with its step, worst step and late steps as last reported.
  Json channel_part(const std::string& channel, const std::vector<FmuSpec>& fmus, Clock::time_point now) const;
  // Output channel -> why its bounds do not hold: an FMU publishing it whose latest report, not
  // stale, shows a worst step longer than its step ("fmu speed_fmu's worst step 12.1 ms exceeds its
  // step 10 ms"); reasons of several FMUs are joined with "; ".
  std::map<std::string, std::string> overruns(const std::vector<FmuSpec>& fmus, Clock::time_point now) const;

 private:
  // Why `fmu`'s latest report flags its output channels, if it does.
  std::optional<std::string> overrun(const FmuSpec& fmu, Clock::time_point now) const;

  std::map<std::string, FmuReport> reports_;  // by FMU name
};

}  // namespace cosmic

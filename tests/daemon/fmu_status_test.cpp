// What cosmic-fmu says about its run (daemon/cosmic-fmu/step_timing, runner_status): late steps
// counted, the reported worst step covering the time since the previous report (one slow step is
// reported once, so cosmicd's run-time flag can end), the fmu_report request as cosmicd reads it,
// and the status line.
#include <gtest/gtest.h>

#include "runner_status.hpp"
#include "step_timing.hpp"

namespace cosmic_fmu {
namespace {

using std::chrono::milliseconds;

TEST(StepTiming, LateStepsAreCountedAndTheReportedWorstStartsAgainAfterEachReport) {
  StepTiming timing;
  timing.record(milliseconds(1), false, {});
  timing.record(milliseconds(12), true, milliseconds(2));  // one slow step, past its deadline
  timing.record(milliseconds(2), false, {});
  const auto first = timing.snapshot(/*take_window=*/true);
  EXPECT_EQ(first.steps, 3u);
  EXPECT_EQ(first.late_steps, 1u);
  EXPECT_EQ(first.worst, milliseconds(12));
  EXPECT_EQ(first.worst_recent, milliseconds(12));
  EXPECT_EQ(first.latest_lateness, milliseconds(2));
  EXPECT_EQ(first.p50, milliseconds(2));

  timing.record(milliseconds(3), false, {});
  const auto second = timing.snapshot(true);
  EXPECT_EQ(second.worst, milliseconds(12));        // since the start, for the log
  EXPECT_EQ(second.worst_recent, milliseconds(3));  // since the previous report
  EXPECT_EQ(timing.snapshot().worst_recent, milliseconds(0));
}

TEST(RunnerStatus, TheReportCarriesWhatCosmicdReads) {
  RunnerStatus status;
  status.state = RunnerState::running;
  status.timing.steps = 1234;
  status.timing.late_steps = 2;
  status.timing.worst = milliseconds(30);
  status.timing.worst_recent = milliseconds(4);
  status.timing.p99 = milliseconds(1);
  status.inputs = {{"speed", 100, 3, 0, 0}, {"command", 7, 0, 0, 0}};
  const auto report = report_request("controller", milliseconds(10), status);
  EXPECT_EQ(report["command"], "fmu_report");
  EXPECT_EQ(report["name"], "controller");
  EXPECT_EQ(report["state"], "running");
  EXPECT_EQ(report["step_ns"], 10'000'000);
  EXPECT_EQ(report["steps"], 1234);
  EXPECT_EQ(report["late_steps"], 2);
  EXPECT_EQ(report["worst_step_ns"], 4'000'000);  // the window's, not the all-time worst
  EXPECT_EQ(report["p99_step_ns"], 1'000'000);
  EXPECT_EQ(report["skipped"], (nlohmann::json{{"speed", 3}, {"command", 0}}));
  EXPECT_EQ(summary_line(milliseconds(10), status),
            "running: 1234 steps of 10 ms, 2 late, step time p50 0 ms p99 1 ms worst 30 ms; input events skipped 3");
}

TEST(RunnerStatus, ALongFailureMessageIsCutAfterAWholeLine) {
  RunnerStatus status;
  status.state = RunnerState::failed;
  const std::string line(100, 'x');
  for (int i = 0; i < 200; ++i) status.message += line + "\n";  // 20,200 bytes
  const std::string message = report_request("every", milliseconds(10), status)["message"];
  EXPECT_LE(message.size(), kMaxReportedMessage + 3);
  EXPECT_EQ(message.substr(message.size() - 5), "x\n...");
  EXPECT_EQ(message.size() % 101, 3u);  // whole lines, then "..."
}

}  // namespace
}  // namespace cosmic_fmu

// cosmic-fmu's runner: one `fmus:` entry of a gateway configuration run as a component (issue 38,
// docs/fmu.md). It extracts the FMU into a private directory, instantiates and initializes it, joins
// its input and output channels on its segment with libcosmic-client, then steps it: paced in real
// time (step k starts at start + k*step; a step that ends after the next one's start is late, and
// the schedule then slips so that the steps after it keep their spacing) or as fast as it goes. An
// FMU that asks to end the simulation (FMI 3.0) ends the run as a stop does.
//
// Threads: run() on the caller's thread (the step thread, named "fmu-step"); the client's receive
// threads hand input events to the stepper's latches; status() from any thread (the reporter's).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "cosmic/client.hpp"
#include "cosmic/fmu_stepper.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/pi_mutex.hpp"
#include "runner_status.hpp"
#include "step_timing.hpp"
#include "work_directory.hpp"

namespace cosmic_fmu {

struct RunnerOptions {
  bool paced = true;                                // false: as fast as possible (against a replay)
  std::uint64_t steps = 0;                          // 0: until stopped
  std::chrono::milliseconds ready_timeout{10'000};  // for the output channels to be carried
  std::string work_parent = "/tmp";                 // where the FMU is extracted
  std::string trace_file;                           // CSV of every step's inputs and outputs; empty: none
  unsigned can_node = 0;                            // the TxNode on a CAN segment
};

class FmuRunner {
 public:
  // Everything up to the first step: extracted, instantiated, parameters set, initialized, channels
  // announced. An error says which part failed and why.
  static cosmic::Result<std::unique_ptr<FmuRunner>> open(const cosmic::Config& config, const cosmic::FmuSpec& spec,
                                                         const RunnerOptions& options, cosmic::Logger& log);
  ~FmuRunner();

  // Waits until the output channels are carried (or the timeout passed: logged, it steps anyway),
  // then steps until `stop` is set or the step count is reached. An error: a step failed (the FMU's
  // log is in status().message).
  cosmic::Result<void> run(const std::atomic<bool>& stop);
  // `take_window`: the report's worst step starts again from now (StepTiming::snapshot).
  RunnerStatus status(bool take_window = false) const;
  const cosmic::FmuSpec& spec() const { return spec_; }

 private:
  FmuRunner(const cosmic::Config& config, const cosmic::FmuSpec& spec, const RunnerOptions& options,
            cosmic::Logger& log, WorkDirectory work)
      : config_(config), spec_(spec), options_(options), log_(log), work_(std::move(work)) {}
  cosmic::Result<void> join_channels();
  cosmic::Result<void> one_step(std::uint64_t index);
  void publish_outputs();
  void trace_header();
  void trace_step(std::uint64_t index);
  void wait_until_carried(const std::atomic<bool>& stop);
  void set_state(RunnerState state, std::string message = {});

  const cosmic::Config& config_;
  const cosmic::FmuSpec& spec_;
  RunnerOptions options_;
  cosmic::Logger& log_;
  WorkDirectory work_;
  cosmic::fmi::OpenedFmu fmu_;
  std::unique_ptr<cosmic::fmi::FmuInstance> instance_;
  std::unique_ptr<cosmic::fmi::FmuStepper> stepper_;
  std::unique_ptr<cosmic::client::Client> client_;
  std::vector<cosmic::client::Channel*> input_channels_;   // by the stepper's input index
  std::vector<cosmic::client::Channel*> output_channels_;  // by the stepper's output index
  std::vector<cosmic::client::Subscription> subscriptions_;
  std::ofstream trace_;
  mutable StepTiming timing_;  // snapshot(take_window) restarts the reported window
  std::atomic<std::uint64_t> publish_errors_{0};
  mutable cosmic::PiMutex status_mutex_;  // the step thread may run SCHED_FIFO, the reporter does not
  RunnerState state_ COSMIC_GUARDED_BY(status_mutex_) = RunnerState::starting;
  std::string message_ COSMIC_GUARDED_BY(status_mutex_);
  std::vector<cosmic::fmi::InputCounters> inputs_ COSMIC_GUARDED_BY(status_mutex_);
  std::vector<cosmic::fmi::OutputCounters> outputs_ COSMIC_GUARDED_BY(status_mutex_);
};

}  // namespace cosmic_fmu

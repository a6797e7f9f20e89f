// How long the FMU's steps take and whether they end before their deadlines (cosmic-fmu; issue 38,
// docs/fmu.md "Timing"). A step's time runs from taking the inputs to the last output published;
// a step is late when it ends after the start of the next one.
//
// Written by the step thread, copied by the status thread under the one mutex (record() holds it
// for a few stores, snapshot() for a copy of 8 KiB; never across I/O).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"

namespace cosmic_fmu {

struct StepTimingSnapshot {
  std::uint64_t steps = 0;
  std::uint64_t late_steps = 0;
  std::chrono::nanoseconds worst{0};         // since the start
  std::chrono::nanoseconds worst_recent{0};  // since the last snapshot that took the window (the report's)
  std::chrono::nanoseconds p50{0};
  std::chrono::nanoseconds p99{0};
  std::chrono::nanoseconds latest_lateness{0};  // of the last late step: how far past its deadline it ended
};

class StepTiming {
 public:
  void record(std::chrono::nanoseconds took, bool late, std::chrono::nanoseconds lateness);
  // The figures so far; `take_window`: worst_recent starts again from now (the reporter's, so that
  // one slow step is reported once, not in every report after it).
  StepTimingSnapshot snapshot(bool take_window = false);

 private:
  // The last kKept step times, for the percentiles of what the FMU does now.
  static constexpr std::size_t kKept = 1024;
  // Priority-inheriting: the step thread may run SCHED_FIFO (--priority), the reporter does not.
  cosmic::PiMutex mutex_;
  std::array<std::int64_t, kKept> recent_ COSMIC_GUARDED_BY(mutex_){};
  StepTimingSnapshot totals_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace cosmic_fmu

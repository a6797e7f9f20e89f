// Keeps a busy real-time thread from starving its CPU. A thread of cosmicd that runs SCHED_FIFO or
// SCHED_RR and stays busy for a whole window (a busy loop: Fast DDS 2.9's flow-controller thread
// was seen spinning forever right after a participant started, inheriting the HRT participant's
// SCHED_FIFO priority and reserved CPU) keeps every thread of lower or equal priority off that CPU
// for good: discovery, the lanes, the HRT path itself. Such a thread is made time-shared (nice 19)
// on the control thread's CPUs, off those reserved for real-time lanes, once, and the reason is
// logged; the rest of the gateway runs on. The kernel's own real-time
// throttling leaves only time-shared threads their 5% and does nothing for the other real-time ones.
//
// Control thread only (cosmicd's loop calls check() every second).
#pragma once

#include <sched.h>
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "cosmic/result.hpp"

namespace cosmicd {

// One thread of the process as the watchdog sees it.
struct ThreadSample {
  pid_t tid = 0;
  std::string name;
  bool realtime = false;     // SCHED_FIFO or SCHED_RR
  std::uint64_t cpu_ns = 0;  // time on a CPU since it started (schedstat)
};

// The judgement, without I/O: which real-time threads were busy for at least `busy_share` of a
// window of at least `window`.
class BusyThreadJudge {
 public:
  explicit BusyThreadJudge(std::chrono::nanoseconds window = std::chrono::seconds(1), double busy_share = 0.9);

  struct Verdict {
    ThreadSample thread;
    double share = 0;  // of the window it was on a CPU
    std::chrono::nanoseconds window{};
  };
  // The samples of every thread taken at `now` (steady clock); the threads to demote.
  std::vector<Verdict> judge(const std::vector<ThreadSample>& samples, std::chrono::nanoseconds now);

 private:
  struct Watch {
    std::uint64_t cpu_ns = 0;
    std::chrono::nanoseconds since{};
  };
  const std::chrono::nanoseconds window_;
  const double busy_share_;
  std::unordered_map<pid_t, Watch> watched_;
};

// The threads of this process (/proc/self/task): scheduling class, and for the real-time ones
// name and CPU time (the others are not read further: the watchdog runs every second). A thread
// that ends while it is read is left out.
std::vector<ThreadSample> sample_process_threads();

// The CPUs a demoted thread goes to: those of the calling (control) thread, without `keep_off`
// (the CPUs reserved for the real-time lanes); all of the calling thread's when that leaves none.
cpu_set_t demoted_thread_cpus(const std::vector<int>& keep_off);

// Makes thread `tid` of this process time-shared at nice 19, on `cpus`; the error names the step
// that failed.
cosmic::Result<void> make_time_shared(pid_t tid, const cpu_set_t& cpus);

// The judge over this process's threads, demoting and describing what it found.
class RealtimeWatchdog {
 public:
  // The CPUs reserved for real-time lanes (gateway.realtime.cpus hrt and srt): a demoted thread
  // is kept off them. Set before the first check().
  void keep_off(std::vector<int> cpus) { keep_off_ = std::move(cpus); }
  // One line per thread demoted (or that could not be), for the log.
  std::vector<std::string> check(std::chrono::nanoseconds now);

 private:
  BusyThreadJudge judge_;
  std::vector<int> keep_off_;
};

}  // namespace cosmicd

// How a gateway thread runs: its name (as shown by ps/top/gdb), its scheduling class and priority,
// and the CPUs it may run on. Applied by the thread itself when it starts.
#pragma once

#include <string>
#include <vector>

namespace cosmic {

struct ThreadPolicy {
  std::string name;       // at most 15 characters are kept (the kernel's limit)
  int fifo_priority = 0;  // 1..99: SCHED_FIFO at that priority; 0: the normal time-sharing class
  int nice = 0;           // for the time-sharing class (positive values need no privilege)
  std::vector<int> cpus;  // empty: any CPU
};

// Whether a thread that runs as `thread` may do the work of a class whose egress lanes run as
// `lane` (send its events) without ranking that work above a higher class: `thread` is
// time-shared (any SCHED_FIFO lane preempts it), or it runs as the lanes do (priority and CPUs).
bool may_do_lane_work(const ThreadPolicy& thread, const ThreadPolicy& lane);

// Applies `policy` to the calling thread. Returns what could not be applied (e.g. "SCHED_FIFO 80:
// Operation not permitted"); the thread runs on with what it got.
std::vector<std::string> apply_thread_policy(const ThreadPolicy& policy);

// Whether a thread of this process may run SCHED_FIFO at `priority` (tried on a short-lived
// thread of its own: privilege, RLIMIT_RTPRIO and the container all decide). Control thread.
bool sched_fifo_permitted(int priority);

// Restricts every thread this process has now to `cpus` (threads they start later inherit it;
// a thread that applies a policy of its own with CPUs moves on to those). Called once at start,
// before the forwarding threads exist. Returns what could not be applied.
std::vector<std::string> place_process_threads(const std::vector<int>& cpus);

}  // namespace cosmic

#include "cosmic/thread_policy.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace cosmic {

std::vector<std::string> apply_thread_policy(const ThreadPolicy& policy) {
  std::vector<std::string> problems;
  if (!policy.name.empty()) {
    const std::string name = policy.name.substr(0, 15);
    if (const int rc = pthread_setname_np(pthread_self(), name.c_str()); rc != 0)
      problems.push_back("name " + name + ": " + std::strerror(rc));
  }
  if (!policy.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (const int cpu : policy.cpus) {
      if (cpu >= 0 && cpu < CPU_SETSIZE) CPU_SET(cpu, &set);
    }
    if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set); rc != 0)
      problems.push_back("CPU affinity: " + std::string(std::strerror(rc)));
  }
  if (policy.fifo_priority > 0) {
    sched_param param{};
    param.sched_priority = policy.fifo_priority;
    if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); rc != 0)
      problems.push_back("SCHED_FIFO " + std::to_string(policy.fifo_priority) + ": " + std::strerror(rc));
  } else if (policy.nice != 0) {
    // setpriority(PRIO_PROCESS, tid) sets the nice value of this one thread on Linux.
    const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
    if (::setpriority(PRIO_PROCESS, tid, policy.nice) != 0)
      problems.push_back("nice " + std::to_string(policy.nice) + ": " + std::strerror(errno));
  }
  return problems;
}

}  // namespace cosmic

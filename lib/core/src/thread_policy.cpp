#include "cosmic/thread_policy.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <dirent.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace cosmic {

bool may_do_lane_work(const ThreadPolicy& thread, const ThreadPolicy& lane) {
  if (thread.fifo_priority == 0) return true;
  return thread.fifo_priority == lane.fifo_priority && thread.cpus == lane.cpus;
}
namespace {
cpu_set_t cpu_set_of(const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) {
    if (cpu >= 0 && cpu < CPU_SETSIZE) CPU_SET(cpu, &set);
  }
  return set;
}
}  // namespace

std::vector<std::string> apply_thread_policy(const ThreadPolicy& policy) {
  std::vector<std::string> problems;
  if (!policy.name.empty()) {
    const std::string name = policy.name.substr(0, 15);
    if (const int rc = pthread_setname_np(pthread_self(), name.c_str()); rc != 0)
      problems.push_back("name " + name + ": " + std::strerror(rc));
  }
  if (!policy.cpus.empty()) {
    const cpu_set_t set = cpu_set_of(policy.cpus);
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

bool sched_fifo_permitted(int priority) {
  if (priority <= 0) return false;
  bool permitted = false;
  std::thread probe([&] {
    sched_param param{};
    param.sched_priority = priority;
    permitted = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  });
  probe.join();
  return permitted;
}

std::vector<std::string> place_process_threads(const std::vector<int>& cpus) {
  std::vector<std::string> problems;
  if (cpus.empty()) return problems;
  const cpu_set_t set = cpu_set_of(cpus);
  DIR* tasks = ::opendir("/proc/self/task");
  if (tasks == nullptr) {
    const int error = errno;
    return {std::string("CPU affinity: /proc/self/task: ") + std::strerror(error)};
  }
  while (const dirent* entry = ::readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    const auto tid = static_cast<pid_t>(std::strtol(entry->d_name, nullptr, 10));
    // A thread that ended since the directory was read is no problem.
    if (::sched_setaffinity(tid, sizeof set, &set) != 0) {
      const int error = errno;  // before any allocation below can change it
      if (error != ESRCH)
        problems.push_back("CPU affinity of thread " + std::to_string(tid) + ": " + std::strerror(error));
    }
  }
  ::closedir(tasks);
  return problems;
}

}  // namespace cosmic

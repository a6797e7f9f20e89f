#include "realtime_watchdog.hpp"

#include <dirent.h>
#include <sched.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <unordered_set>

namespace cosmicd {

BusyThreadJudge::BusyThreadJudge(std::chrono::nanoseconds window, double busy_share)
    : window_(window), busy_share_(busy_share) {}

std::vector<BusyThreadJudge::Verdict> BusyThreadJudge::judge(const std::vector<ThreadSample>& samples,
                                                             std::chrono::nanoseconds now) {
  std::vector<Verdict> out;
  std::unordered_set<pid_t> seen;
  for (const ThreadSample& s : samples) {
    if (!s.realtime) continue;  // a time-shared thread cannot starve anyone
    seen.insert(s.tid);
    auto [it, fresh] = watched_.try_emplace(s.tid, Watch{s.cpu_ns, now});
    Watch& w = it->second;
    // A new thread, or a thread id taken again by a new thread (its CPU time starts over).
    if (fresh || s.cpu_ns < w.cpu_ns) {
      w = Watch{s.cpu_ns, now};
      continue;
    }
    const auto elapsed = now - w.since;
    if (elapsed < window_) continue;
    const double share = static_cast<double>(s.cpu_ns - w.cpu_ns) / static_cast<double>(elapsed.count());
    if (share >= busy_share_) out.push_back(Verdict{s, share, elapsed});
    w = Watch{s.cpu_ns, now};
  }
  for (auto it = watched_.begin(); it != watched_.end();)
    it = seen.contains(it->first) ? std::next(it) : watched_.erase(it);
  return out;
}

namespace {

std::optional<std::string> read_first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) return std::nullopt;
  return line;
}

}  // namespace

std::vector<ThreadSample> sample_process_threads() {
  std::vector<ThreadSample> out;
  DIR* tasks = ::opendir("/proc/self/task");
  if (tasks == nullptr) return out;
  while (const dirent* entry = ::readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    const std::string dir = std::string("/proc/self/task/") + entry->d_name;
    ThreadSample s;
    s.tid = static_cast<pid_t>(std::strtol(entry->d_name, nullptr, 10));
    const int policy = ::sched_getscheduler(s.tid);
    if (policy < 0) continue;  // ended meanwhile
    s.realtime = (policy & ~SCHED_RESET_ON_FORK) == SCHED_FIFO || (policy & ~SCHED_RESET_ON_FORK) == SCHED_RR;
    if (!s.realtime) {
      out.push_back(std::move(s));
      continue;
    }
    const auto schedstat = read_first_line(dir + "/schedstat");  // "<ns on CPU> <ns waiting> <slices>"
    if (!schedstat) continue;
    s.cpu_ns = std::strtoull(schedstat->c_str(), nullptr, 10);
    s.name = read_first_line(dir + "/comm").value_or("?");
    out.push_back(std::move(s));
  }
  ::closedir(tasks);
  return out;
}

cpu_set_t demoted_thread_cpus(const std::vector<int>& keep_off) {
  cpu_set_t control;
  CPU_ZERO(&control);
  if (::sched_getaffinity(0, sizeof control, &control) != 0) {
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) CPU_SET(cpu, &control);  // unknown: any CPU
  }
  cpu_set_t out = control;
  for (const int cpu : keep_off) {
    if (cpu >= 0 && cpu < CPU_SETSIZE) CPU_CLR(cpu, &out);
  }
  return CPU_COUNT(&out) > 0 ? out : control;
}

cosmic::Result<void> make_time_shared(pid_t tid, const cpu_set_t& cpus) {
  sched_param param{};
  param.sched_priority = 0;
  if (::sched_setscheduler(tid, SCHED_OTHER, &param) != 0)
    return cosmic::Error::from_errno("sched_setscheduler", errno);
  // setpriority(PRIO_PROCESS, tid) sets the nice value of this one thread on Linux.
  if (::setpriority(PRIO_PROCESS, static_cast<id_t>(tid), 19) != 0) return cosmic::Error::from_errno("nice 19", errno);
  // Onto the control thread's CPUs. Time-shared but alone on a reserved CPU, a loop that retakes
  // a mutex as soon as it lets it go still shuts out a waiter on another CPU, which wakes too
  // late every time (Fast DDS 2.9's flow controller does that to the thread removing a matched
  // reader); sharing the waiter's CPUs, the kernel preempts it for the waiter.
  if (::sched_setaffinity(tid, sizeof cpus, &cpus) != 0)
    return cosmic::Error::from_errno("time-shared, but its CPU affinity", errno);
  return {};
}

std::vector<std::string> RealtimeWatchdog::check(std::chrono::nanoseconds now) {
  std::vector<std::string> lines;
  for (const auto& v : judge_.judge(sample_process_threads(), now)) {
    char share[16];
    std::snprintf(share, sizeof share, "%.0f%%", 100.0 * v.share);
    std::string line = "thread " + v.thread.name + " (" + std::to_string(v.thread.tid) + ") ran real-time for " +
                       share + " of the last " + std::to_string(v.window.count() / 1'000'000) +
                       " ms, a busy loop that starves every thread below it on its CPU: ";
    if (const cosmic::Result<void> shared = make_time_shared(v.thread.tid, demoted_thread_cpus(keep_off_)); !shared) {
      line += "it could not be made time-shared on the control thread's CPUs (" + shared.error().text + ")";
    } else {
      line += "it runs time-shared (nice 19), on the control thread's CPUs, from now on";
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

}  // namespace cosmicd

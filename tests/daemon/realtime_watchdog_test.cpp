// cosmicd's real-time watchdog (daemon/cosmicd/realtime_watchdog.hpp): a real-time thread busy
// for a whole window is made time-shared; nothing else is touched.
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cosmic/thread_policy.hpp"
#include "realtime_watchdog.hpp"

namespace cosmicd {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

ThreadSample sample(pid_t tid, bool realtime, std::uint64_t cpu_ms) {
  return ThreadSample{tid, "t" + std::to_string(tid), realtime, cpu_ms * 1'000'000};
}

TEST(BusyThreadJudge, ARealtimeThreadBusyForTheWholeWindowIsNamed) {
  BusyThreadJudge judge(milliseconds(1000), 0.9);
  EXPECT_TRUE(judge.judge({sample(7, true, 100)}, milliseconds(0)).empty());    // first sight
  EXPECT_TRUE(judge.judge({sample(7, true, 600)}, milliseconds(500)).empty());  // window not over
  const auto verdicts = judge.judge({sample(7, true, 1050)}, milliseconds(1000));
  ASSERT_EQ(verdicts.size(), 1u);
  EXPECT_EQ(verdicts[0].thread.tid, 7);
  EXPECT_DOUBLE_EQ(verdicts[0].share, 0.95);
  EXPECT_EQ(verdicts[0].window, milliseconds(1000));
}

TEST(BusyThreadJudge, BusyTimeSharedAndModeratelyBusyRealtimeThreadsAreLeftAlone) {
  BusyThreadJudge judge(milliseconds(1000), 0.9);
  judge.judge({sample(1, false, 0), sample(2, true, 0)}, milliseconds(0));
  // 100% time-shared; 85% real-time (an HRT lane under a heavy but admitted load).
  EXPECT_TRUE(judge.judge({sample(1, false, 1000), sample(2, true, 850)}, milliseconds(1000)).empty());
}

TEST(BusyThreadJudge, AThreadIdTakenAgainStartsItsWindowOver) {
  BusyThreadJudge judge(milliseconds(1000), 0.9);
  judge.judge({sample(9, true, 5000)}, milliseconds(0));
  // Thread 9 ended and a new thread 9 began: its CPU time is below the old one's.
  EXPECT_TRUE(judge.judge({sample(9, true, 10)}, milliseconds(1000)).empty());
  EXPECT_TRUE(judge.judge({sample(9, true, 500)}, milliseconds(1500)).empty());
  EXPECT_EQ(judge.judge({sample(9, true, 1000)}, milliseconds(2000)).size(), 1u);
}

TEST(BusyThreadJudge, AThreadThatLeftRealtimeIsForgotten) {
  BusyThreadJudge judge(milliseconds(1000), 0.9);
  judge.judge({sample(4, true, 0)}, milliseconds(0));
  judge.judge({sample(4, false, 500)}, milliseconds(500));
  // Real-time again: watched from here, not from its first sight.
  EXPECT_TRUE(judge.judge({sample(4, true, 990)}, milliseconds(1000)).empty());
}

// The CPUs the process may use, in order.
std::vector<int> allowed_cpus(const cpu_set_t& set) {
  std::vector<int> out;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) out.push_back(cpu);
  return out;
}

cpu_set_t set_of(const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) CPU_SET(cpu, &set);
  return set;
}

TEST(RealtimeWatchdog, ADemotedThreadGoesToTheControlThreadsCpusOffTheReservedOnes) {
  cpu_set_t mine;
  ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
  const std::vector<int> cpus = allowed_cpus(mine);
  ASSERT_FALSE(cpus.empty());
  cpu_set_t expected = mine;
  CPU_CLR(cpus.back(), &expected);
  cpu_set_t got = demoted_thread_cpus({cpus.back()});
  if (cpus.size() > 1) {
    EXPECT_TRUE(CPU_EQUAL(&got, &expected));  // the reserved one left out
  } else {
    EXPECT_TRUE(CPU_EQUAL(&got, &mine));  // nothing else to go to: where the control thread runs
  }
  got = demoted_thread_cpus({});
  EXPECT_TRUE(CPU_EQUAL(&got, &mine));
  got = demoted_thread_cpus({-1, CPU_SETSIZE});  // out of range: ignored
  EXPECT_TRUE(CPU_EQUAL(&got, &mine));
}

// Two threads to look at: one real-time and asleep on `fifo_cpus`, one time-shared and busy for
// a while. Stopped, joined and the test thread's CPUs restored on every way out of the test.
class ThreadsToWatch {
 public:
  explicit ThreadsToWatch(const cpu_set_t& fifo_cpus) {
    sched_getaffinity(0, sizeof saved_, &saved_);
    fifo_ = std::thread([this, fifo_cpus] {
      pthread_setaffinity_np(pthread_self(), sizeof fifo_cpus, &fifo_cpus);
      sched_param param{};
      param.sched_priority = 10;
      pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
      pthread_setname_np(pthread_self(), "wd-fifo");
      fifo_tid.store(static_cast<pid_t>(::syscall(SYS_gettid)));
      while (run_.load()) std::this_thread::sleep_for(milliseconds(5));
    });
    busy_ = std::thread([this] {
      busy_tid.store(static_cast<pid_t>(::syscall(SYS_gettid)));
      const auto until = std::chrono::steady_clock::now() + milliseconds(200);
      while (std::chrono::steady_clock::now() < until) {
      }
      while (run_.load()) std::this_thread::sleep_for(milliseconds(5));
    });
    while (fifo_tid.load() == 0 || busy_tid.load() == 0) std::this_thread::yield();
  }
  ~ThreadsToWatch() {
    run_.store(false);
    fifo_.join();
    busy_.join();
    sched_setaffinity(0, sizeof saved_, &saved_);
  }
  std::atomic<pid_t> fifo_tid{0};
  std::atomic<pid_t> busy_tid{0};

 private:
  cpu_set_t saved_;
  std::atomic<bool> run_{true};
  std::thread fifo_, busy_;
};

// The watchdog's eyes and hands on real threads. (Not a real SCHED_FIFO busy loop: on this
// 2-CPU VM one stalled the whole machine for minutes, kernel threads of its CPU included.)
TEST(RealtimeWatchdog, SeesRealtimeThreadsAndTheirCpuTimeAndMakesOneTimeShared) {
  // Only a process that may use SCHED_FIFO can make a real-time thread to look at; scripts/test and
  // CI run as root, where it runs. A developer's unprivileged run skips it and says why.
  if (!cosmic::sched_fifo_permitted(10))
    GTEST_SKIP() << "SCHED_FIFO is not permitted to this process (no CAP_SYS_NICE, RLIMIT_RTPRIO 0)";
  // As cosmicd's reserved placement, where the process may use two CPUs or more: the real-time
  // thread on the last one, the test's (control) thread on the others.
  cpu_set_t mine;
  ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
  const std::vector<int> cpus = allowed_cpus(mine);
  const std::vector<int> reserved{cpus.back()};
  std::vector<int> control(cpus.begin(), cpus.end() - (cpus.size() > 1 ? 1 : 0));
  ThreadsToWatch threads(set_of(reserved));
  const cpu_set_t control_set = set_of(control);
  ASSERT_EQ(sched_setaffinity(0, sizeof control_set, &control_set), 0);
  std::this_thread::sleep_for(milliseconds(300));
  const auto samples = sample_process_threads();
  const ThreadSample* f = nullptr;
  const ThreadSample* b = nullptr;
  for (const auto& sample : samples) {
    if (sample.tid == threads.fifo_tid.load()) f = &sample;
    if (sample.tid == threads.busy_tid.load()) b = &sample;
  }
  ASSERT_NE(f, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_TRUE(f->realtime);
  EXPECT_EQ(f->name, "wd-fifo");
  EXPECT_FALSE(b->realtime);
  // The real-time one's CPU time is read: what the judge weighs.
  const auto again = sample_process_threads();
  for (const auto& sample : again) {
    if (sample.tid == f->tid) {
      EXPECT_GE(sample.cpu_ns, f->cpu_ns);
    }
  }

  EXPECT_TRUE(make_time_shared(threads.fifo_tid.load(), demoted_thread_cpus(reserved)).ok());
  EXPECT_EQ(sched_getscheduler(threads.fifo_tid.load()), SCHED_OTHER);
  errno = 0;
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(threads.fifo_tid.load())), 19);
  cpu_set_t now_on;
  ASSERT_EQ(sched_getaffinity(threads.fifo_tid.load(), sizeof now_on, &now_on), 0);
  EXPECT_TRUE(CPU_EQUAL(&now_on, &control_set)) << "moved next to the control thread";
}

}  // namespace
}  // namespace cosmicd

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
  EXPECT_TRUE(judge.judge({sample(7, true, 100)}, milliseconds(0)).empty());  // first sight
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

// The watchdog's eyes and hands on real threads. (Not a real SCHED_FIFO busy loop: on this
// 2-CPU VM one stalled the whole machine for minutes, kernel threads of its CPU included.)
TEST(RealtimeWatchdog, SeesRealtimeThreadsAndTheirCpuTimeAndMakesOneTimeShared) {
  // Only a process that may use SCHED_FIFO can make a real-time thread to look at; scripts/test and
  // CI run as root, where it runs. A developer's unprivileged run skips it and says why.
  if (!cosmic::sched_fifo_permitted(10))
    GTEST_SKIP() << "SCHED_FIFO is not permitted to this process (no CAP_SYS_NICE, RLIMIT_RTPRIO 0)";
  std::atomic<bool> run{true};
  std::atomic<pid_t> fifo_tid{0};
  std::atomic<pid_t> busy_tid{0};
  // The real-time thread sits on the last CPU, the test's own thread on the others (as cosmicd's
  // HRT threads and its control thread in the reserved placement), when there are two.
  const int cpu_count = static_cast<int>(std::thread::hardware_concurrency());
  cpu_set_t control_cpus, saved_cpus;
  ASSERT_EQ(sched_getaffinity(0, sizeof saved_cpus, &saved_cpus), 0);
  CPU_ZERO(&control_cpus);
  for (int cpu = 0; cpu < std::max(1, cpu_count - 1); ++cpu) CPU_SET(cpu, &control_cpus);
  ASSERT_EQ(sched_setaffinity(0, sizeof control_cpus, &control_cpus), 0);
  std::thread fifo([&] {  // real-time, asleep
    cpu_set_t last;
    CPU_ZERO(&last);
    CPU_SET(std::max(0, cpu_count - 1), &last);
    pthread_setaffinity_np(pthread_self(), sizeof last, &last);
    sched_param param{};
    param.sched_priority = 10;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    pthread_setname_np(pthread_self(), "wd-fifo");
    fifo_tid.store(static_cast<pid_t>(::syscall(SYS_gettid)));
    while (run.load()) std::this_thread::sleep_for(milliseconds(5));
  });
  std::thread busy([&] {  // time-shared, busy for a while
    busy_tid.store(static_cast<pid_t>(::syscall(SYS_gettid)));
    const auto until = std::chrono::steady_clock::now() + milliseconds(200);
    while (std::chrono::steady_clock::now() < until) {
    }
    while (run.load()) std::this_thread::sleep_for(milliseconds(5));
  });
  while (fifo_tid.load() == 0 || busy_tid.load() == 0) std::this_thread::yield();
  std::this_thread::sleep_for(milliseconds(300));
  const auto samples = sample_process_threads();
  const ThreadSample* f = nullptr;
  const ThreadSample* b = nullptr;
  for (const auto& sample : samples) {
    if (sample.tid == fifo_tid.load()) f = &sample;
    if (sample.tid == busy_tid.load()) b = &sample;
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

  EXPECT_EQ(make_time_shared(fifo_tid.load()), std::nullopt);
  EXPECT_EQ(sched_getscheduler(fifo_tid.load()), SCHED_OTHER);
  errno = 0;
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(fifo_tid.load())), 19);
  cpu_set_t now_on;
  ASSERT_EQ(sched_getaffinity(fifo_tid.load(), sizeof now_on, &now_on), 0);
  EXPECT_TRUE(CPU_EQUAL(&now_on, &control_cpus));  // moved next to the control thread
  sched_setaffinity(0, sizeof saved_cpus, &saved_cpus);
  run.store(false);
  fifo.join();
  busy.join();
}

}  // namespace
}  // namespace cosmicd

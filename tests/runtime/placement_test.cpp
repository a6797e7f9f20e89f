// gateway.realtime.cpus by kind of thread: the lanes of each class run on their class's CPUs, and
// place_process_threads() moves every thread of the process (cosmicd's `other`).
#include <gtest/gtest.h>
#include <sched.h>

#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {
namespace {

class SilentLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

std::vector<int> cpus_of(pid_t tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(sched_getaffinity(tid, sizeof set, &set), 0) << "thread " << tid;
  std::vector<int> out;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) out.push_back(cpu);
  return out;
}

// The CPUs of every thread of this process, by thread name.
std::multimap<std::string, std::vector<int>> threads_by_name() {
  std::multimap<std::string, std::vector<int>> out;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string comm;
    std::getline(std::ifstream(task.path() / "comm"), comm);
    out.emplace(comm, cpus_of(static_cast<pid_t>(std::stol(task.path().filename().string()))));
  }
  return out;
}

int last_cpu() { return static_cast<int>(std::thread::hardware_concurrency()) - 1; }

// The placement tests skip on a machine with one CPU: there, "the HRT CPU" and "the others" are
// the same CPU and no placement can be told from another. The project's machines and CI have two.

TEST(PlacementTest, EachClassOfLanesRunsOnItsOwnCpus) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "needs two CPUs";
  const std::vector<int> everywhere = cpus_of(0);
  const std::string last = std::to_string(last_cpu());
  const std::string yaml = "gateway: {name: gw, realtime: {cpus: {hrt: [" + last + "], nrt: [0]}}}\n" +
                           R"(segments:
  - {name: lan, type: dds, latency_bound: 1ms, realtime: true}
  - {name: rt, type: dds, domain: 1, latency_bound: 1ms, realtime: true}
channels:
  - {name: distance, subject: 7, class: hrt, period: 10ms, reaction_time: 50ms, payload: 4B, publishers: [lan], subscribers: [rt]}
  - {name: camera, subject: 8, class: srt, period: 10ms, reaction_time: 50ms, payload: 4B, publishers: [lan], subscribers: [rt]}
  - {name: log, subject: 9, class: nrt, payload: 4B, publishers: [lan], subscribers: [rt]}
)";
  SilentLogger log;
  Gateway gateway(
      [&](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
        return std::make_unique<MemoryAdapter>(spec.name);
      },
      log, 0x42);
  const auto parsed = parse_config(yaml, "placement.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.errors[0].to_string();
  ASSERT_TRUE(gateway.start(parsed.config).applied);
  // A lane thread applies its policy as it starts: wait until each class has one that did.
  const auto placed = [&](const std::string& name, const std::vector<int>& want) {
    for (auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
         std::chrono::steady_clock::now() < deadline;) {
      const auto threads = threads_by_name();
      const auto [first, end] = threads.equal_range(name);
      if (first != end && std::all_of(first, end, [&](const auto& t) { return t.second == want; })) return true;
      std::this_thread::yield();
    }
    return false;
  };
  EXPECT_TRUE(placed("hrt:rt", {last_cpu()})) << "the HRT lane on the HRT CPU";
  EXPECT_TRUE(placed("nrt:rt", {0})) << "the NRT lane off it";
  EXPECT_TRUE(placed("srt:rt", everywhere)) << "a class without CPUs runs anywhere";
  gateway.stop();
}

// Time-shared NRT lanes yield (nice 10) while an HRT or SRT lane is time-shared too; once both
// run SCHED_FIFO, NRT lanes run at nice 0 like the receive threads that feed them.
TEST(PlacementTest, NrtLanesYieldOnlyWhileAHigherClassIsTimeShared) {
  const auto nrt_nice = [](int hrt, int srt) {
    GatewaySpec gateway;
    gateway.realtime.hrt_priority = hrt;
    gateway.realtime.srt_priority = srt;
    return router_limits(gateway).lane_threads[static_cast<std::size_t>(ChannelClass::nrt)].nice;
  };
  EXPECT_EQ(nrt_nice(0, 0), 10);
  EXPECT_EQ(nrt_nice(80, 0), 10) << "SRT lanes are time-shared: NRT yields to them";
  // Both granted (the tests run as root in scripts/test); without the privilege they stay time-shared.
  EXPECT_EQ(nrt_nice(80, 60), sched_fifo_permitted(80) ? 0 : 10);
}

// A receive thread may send a class's events itself (EgressLane::push_or_send) only where that
// ranks the work above no higher class: time-shared (any SCHED_FIFO lane preempts it), or
// running exactly as that class's lanes do.
TEST(PlacementTest, AReceiveThreadDoesALanesWorkOnlyWhereItRanksNoHigher) {
  const ThreadPolicy nrt_lane{"nrt", 0, 10, {}};
  EXPECT_TRUE(may_do_lane_work(ThreadPolicy{"rx", 0, 0, {}}, nrt_lane)) << "time-shared";
  EXPECT_FALSE(may_do_lane_work(ThreadPolicy{"rx", 70, 0, {}}, nrt_lane))
      << "SCHED_FIFO 70 would write NRT events above SRT lanes";
  const ThreadPolicy srt_lane{"srt", 60, 0, {1}};
  EXPECT_TRUE(may_do_lane_work(ThreadPolicy{"rx", 60, 0, {1}}, srt_lane));
  EXPECT_FALSE(may_do_lane_work(ThreadPolicy{"rx", 60, 0, {0}}, srt_lane)) << "another CPU";
  EXPECT_FALSE(may_do_lane_work(ThreadPolicy{"rx", 61, 0, {1}}, srt_lane)) << "a higher priority";
}

TEST(PlacementTest, PlaceProcessThreadsMovesEveryThreadThatExists) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "needs two CPUs";
  const std::vector<int> everywhere = cpus_of(0);
  std::mutex mutex;
  std::condition_variable changed;
  bool placed = false;
  pid_t other_tid = 0;
  std::vector<int> seen_by_other;
  std::thread other([&] {
    std::unique_lock lock(mutex);
    other_tid = gettid();
    changed.notify_all();
    changed.wait(lock, [&] { return placed; });
    seen_by_other = cpus_of(0);
  });
  {
    std::unique_lock lock(mutex);
    changed.wait(lock, [&] { return other_tid != 0; });
  }
  EXPECT_TRUE(place_process_threads({last_cpu()}).empty());
  EXPECT_EQ(cpus_of(0), std::vector<int>{last_cpu()});
  {
    std::lock_guard lock(mutex);
    placed = true;
    changed.notify_all();
  }
  other.join();
  EXPECT_EQ(seen_by_other, std::vector<int>{last_cpu()}) << "a thread that already ran is moved too";
  EXPECT_TRUE(place_process_threads({}).empty()) << "no CPUs: nothing to do";
  EXPECT_EQ(cpus_of(0), std::vector<int>{last_cpu()});
  EXPECT_TRUE(place_process_threads(everywhere).empty());  // as before, for the tests after this one
}

}  // namespace
}  // namespace cosmic

// SnapshotRelay: /metrics snapshots are taken only when scraped, at most one per reuse window,
// shared by concurrent scrapes; a silent owner or a detach never leaves a scrape hanging.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "metrics_relay.hpp"

namespace cosmicd {
namespace {

using namespace std::chrono_literals;
using Relay = SnapshotRelay<int>;

// A clock the test moves by hand.
struct ManualClock {
  std::atomic<Relay::Clock::rep> ticks{1'000'000'000};
  Relay::Clock::time_point now() const { return Relay::Clock::time_point(Relay::Clock::duration(ticks.load())); }
  void advance(Relay::Clock::duration d) { ticks += d.count(); }
};

// Stands in for cosmicd's control loop: answers every ask with the next number, on its own thread.
class Owner {
 public:
  explicit Owner(Relay& relay) : relay_(relay), thread_([this] { run(); }) {
    relay_.attach([this] {
      std::lock_guard lock(mutex_);
      ++pending_;
      wake_.notify_one();
    });
  }
  ~Owner() {
    relay_.detach();
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  int taken() const { return taken_.load(); }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [&] { return stop_ || pending_ > 0; });
      if (stop_) return;
      --pending_;
      lock.unlock();
      relay_.publish(++taken_);
      lock.lock();
    }
  }

  Relay& relay_;
  std::mutex mutex_;
  std::condition_variable wake_;
  int pending_ = 0;
  bool stop_ = false;
  std::atomic<int> taken_{0};
  std::thread thread_;
};

Relay::Options options(ManualClock& clock, Relay::Clock::duration wait_for = 60s) {
  Relay::Options o;
  o.reuse_for = 100ms;
  o.wait_for = wait_for;
  o.now = [&clock] { return clock.now(); };
  return o;
}

TEST(MetricsRelay, NothingIsTakenWhileNobodyScrapes) {
  ManualClock clock;
  Relay relay(options(clock));
  {
    Owner owner(relay);
    clock.advance(10s);
    EXPECT_EQ(owner.taken(), 0);
  }
  EXPECT_EQ(relay.asked(), 0u);
}

TEST(MetricsRelay, AScrapeGetsASnapshotTakenForIt) {
  ManualClock clock;
  Relay relay(options(clock));
  Owner owner(relay);
  const auto first = relay.get();
  ASSERT_TRUE(first);
  EXPECT_EQ(*first, 1);
  EXPECT_EQ(relay.asked(), 1u);
}

TEST(MetricsRelay, ScrapesWithinTheReuseWindowShareOneSnapshot) {
  ManualClock clock;
  Relay relay(options(clock));
  Owner owner(relay);
  const auto first = relay.get();
  clock.advance(99ms);
  EXPECT_EQ(relay.get(), first);
  EXPECT_EQ(relay.asked(), 1u);
  clock.advance(1ms);  // the window is over: the next scrape gets fresh numbers
  const auto second = relay.get();
  ASSERT_TRUE(second);
  EXPECT_EQ(*second, 2);
  EXPECT_EQ(relay.asked(), 2u);
  EXPECT_EQ(owner.taken(), 2);
}

TEST(MetricsRelay, ConcurrentScrapesAskOnce) {
  ManualClock clock;
  Relay relay(options(clock));
  // The owner answers only when told, so every scrape arrives while the request is outstanding.
  std::atomic<int> asks{0};
  relay.attach([&] { ++asks; });
  std::vector<std::thread> scrapers;
  std::vector<std::shared_ptr<const int>> got(4);
  for (std::size_t i = 0; i < got.size(); ++i) scrapers.emplace_back([&, i] { got[i] = relay.get(); });
  while (asks.load() == 0) std::this_thread::yield();
  relay.publish(7);
  for (auto& t : scrapers) t.join();
  EXPECT_EQ(asks.load(), 1);
  for (const auto& snapshot : got) {
    ASSERT_TRUE(snapshot);
    EXPECT_EQ(*snapshot, 7);
  }
  relay.detach();
}

TEST(MetricsRelay, ASilentOwnerCostsAScrapeAtMostTheWaitLimit) {
  ManualClock clock;
  Relay relay(options(clock, 50ms));
  relay.attach([] {});  // never answers
  const auto started = std::chrono::steady_clock::now();
  EXPECT_FALSE(relay.get());  // nothing ever taken: the endpoint answers 503
  EXPECT_LT(std::chrono::steady_clock::now() - started, 5s);
  relay.publish(3);
  clock.advance(1s);
  const auto stale = relay.get();  // asks again, gets no answer, serves the last one
  ASSERT_TRUE(stale);
  EXPECT_EQ(*stale, 3);
  EXPECT_EQ(relay.asked(), 2u);
  relay.detach();
}

TEST(MetricsRelay, DetachAnswersAWaitingScrapeAtOnce) {
  ManualClock clock;
  Relay relay(options(clock, std::chrono::hours(1)));
  std::atomic<int> asks{0};
  relay.attach([&] { ++asks; });
  relay.publish(5);
  clock.advance(1s);
  std::shared_ptr<const int> got;
  std::thread scraper([&] { got = relay.get(); });
  while (asks.load() == 0) std::this_thread::yield();
  relay.detach();
  scraper.join();  // hangs for an hour if detach did not wake it
  ASSERT_TRUE(got);
  EXPECT_EQ(*got, 5);
  EXPECT_EQ(relay.get(), got);  // detached: never asks again
  EXPECT_EQ(asks.load(), 1);
}

}  // namespace
}  // namespace cosmicd

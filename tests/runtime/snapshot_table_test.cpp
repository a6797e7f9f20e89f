// The adapters' snapshot table (cosmic/snapshot_table.hpp): readers keep the table they took,
// publish() changes what later readers see, and retire() hands an old table back only after its
// last reading has ended.
#include "cosmic/snapshot_table.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <thread>

namespace cosmic {
namespace {

using Table = std::map<int, std::string>;

TEST(SnapshotTable, AReadingKeepsTheTableItTookWhileLaterReadingsSeeTheNextOne) {
  SnapshotTable<Table> table(Table{{1, "one"}});
  const auto before = table.read();
  auto replaced = table.publish(Table{{2, "two"}});
  ASSERT_TRUE(replaced);
  EXPECT_EQ(before->count(1), 1u);
  EXPECT_EQ(before->count(2), 0u);
  const auto after = table.read();
  EXPECT_EQ(after->count(1), 0u);
  EXPECT_EQ((*after).at(2), "two");
  EXPECT_EQ(table.current_for_publisher().at(2), "two");
}

TEST(SnapshotTable, RetireGivesTheOldTableBackAtOnceWhenNobodyReadsIt) {
  SnapshotTable<Table> table(Table{{1, "one"}});
  { const auto reading = table.read(); }
  const Table old = SnapshotTable<Table>::retire(table.publish(Table{}));
  EXPECT_EQ(old.at(1), "one");
}

TEST(SnapshotTable, RetireWaitsForTheLastReadingOfTheOldTable) {
  SnapshotTable<Table> table(Table{{1, "one"}});
  std::mutex mutex;
  std::condition_variable changed;
  bool reading_taken = false;
  bool may_end = false;
  std::atomic<bool> reading_ended{false};
  std::thread reader([&] {
    auto reading = table.read();
    {
      std::unique_lock lock(mutex);
      reading_taken = true;
      changed.notify_all();
      changed.wait(lock, [&] { return may_end; });
    }
    EXPECT_EQ(reading->at(1), "one");  // still the old table, though a new one was published
    reading_ended = true;              // the Reading ends right after this
  });
  {
    std::unique_lock lock(mutex);
    changed.wait(lock, [&] { return reading_taken; });
  }
  auto replaced = table.publish(Table{{2, "two"}});
  std::atomic<bool> retired{false};
  bool ended_before_retire_returned = false;
  Table old;
  std::thread control([&] {
    old = SnapshotTable<Table>::retire(std::move(replaced));
    ended_before_retire_returned = reading_ended.load();
    retired = true;
  });
  // While the reading lasts, retire() must not come back (a broken one returns in microseconds).
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
  while (std::chrono::steady_clock::now() < until) {
    ASSERT_FALSE(retired.load());
    std::this_thread::yield();
  }
  {
    std::lock_guard lock(mutex);
    may_end = true;
  }
  changed.notify_all();
  reader.join();
  control.join();
  EXPECT_TRUE(ended_before_retire_returned);
  EXPECT_EQ(old.at(1), "one");
}

TEST(SnapshotTable, ManyReadersAndRepublishingNeverShowAHalfBuiltTable) {
  // Each table maps 0..9 to one and the same value: a reader seeing two values saw two tables.
  auto make = [](int version) {
    Table t;
    for (int k = 0; k < 10; ++k) t[k] = std::to_string(version);
    return t;
  };
  SnapshotTable<Table> table(make(0));
  std::atomic<bool> stop{false};
  std::atomic<int> mixed{0};
  std::vector<std::thread> readers;
  for (int r = 0; r < 3; ++r) {
    readers.emplace_back([&] {
      while (!stop.load()) {
        const auto reading = table.read();
        for (const auto& [k, v] : *reading)
          if (v != reading->begin()->second) ++mixed;
      }
    });
  }
  for (int version = 1; version <= 200; ++version) {
    const Table old = SnapshotTable<Table>::retire(table.publish(make(version)));
    EXPECT_EQ(old.at(0), std::to_string(version - 1));
  }
  stop = true;
  for (auto& t : readers) t.join();
  EXPECT_EQ(mixed.load(), 0);
}

}  // namespace
}  // namespace cosmic

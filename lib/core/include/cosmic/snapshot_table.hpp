// A table that forwarding and send paths read and the control thread replaces (the router's route
// table, the DDS adapter's writers, the LCM adapter's channels): the next table is built outside any lock, publish()
// swaps it in under a priority-inheriting mutex (a pointer swap), and a reader takes the current table under that mutex
// (a pointer copy and a counter) and then uses it with no lock held: a send on it may write to the network for as long
// as the transport takes, and no other thread waits for that.
//
// Who owns what: the SnapshotTable shares the current table with every Reading of it; a table lives
// until the last of its owners lets go (a Replaced that is never retired included), so no order of
// destruction can free a table under a reader. publish() hands the replaced table to the control
// thread, whose retire() waits until the last Reading of it has ended (readers hold one for one
// send, microseconds) and then gives the table back to be torn down there: what a transport must
// close (a DDS DataWriter, a socket) is closed on the control thread, never on a forwarding thread
// that happened to read last.
//
// Threads: read() from any thread (the egress lanes, receive threads sending in their place, a
// component's threads); publish() and retire()
// from one control thread at a time.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>
#include <utility>

#include "cosmic/pi_mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

template <class Table>
class SnapshotTable {
  struct Node {
    explicit Node(Table t) : table(std::move(t)) {}
    Table table;
    // Readings of this node still running; only ever raised under the SnapshotTable's mutex, so
    // once the node is no longer current the count can only fall.
    std::atomic<std::uint32_t> readers{0};
  };

 public:
  // The table one reader took: valid, and unchanged, for the Reading's lifetime.
  class Reading {
   public:
    Reading(const Reading&) = delete;
    Reading& operator=(const Reading&) = delete;
    Reading(Reading&& other) noexcept = default;
    Reading& operator=(Reading&&) = delete;
    ~Reading() {
      // release: what this reader did with the table happens before retire() hands it back.
      if (node_ != nullptr) node_->readers.fetch_sub(1, std::memory_order_release);
    }
    const Table& operator*() const { return node_->table; }
    const Table* operator->() const { return &node_->table; }

   private:
    friend class SnapshotTable;
    explicit Reading(std::shared_ptr<Node> node) : node_(std::move(node)) {}
    std::shared_ptr<Node> node_;  // moved from: null, and its destructor does nothing
  };

  // The control thread's hold on a replaced table; retire() turns it back into the table.
  class Replaced {
   public:
    Replaced() = default;
    explicit operator bool() const { return node_ != nullptr; }

   private:
    friend class SnapshotTable;
    explicit Replaced(std::shared_ptr<Node> node) : node_(std::move(node)) {}
    std::shared_ptr<Node> node_;
  };

  explicit SnapshotTable(Table initial = Table{}) : current_(std::make_shared<Node>(std::move(initial))) {}
  SnapshotTable(const SnapshotTable&) = delete;
  SnapshotTable& operator=(const SnapshotTable&) = delete;

  Reading read() const COSMIC_EXCLUDES(mutex_) {
    PiLock lock(mutex_);
    current_->readers.fetch_add(1, std::memory_order_relaxed);
    return Reading(current_);  // a reference count raised under the mutex: no allocation
  }

  // Makes `next` current; readers from now on see it. The old table is handed back.
  [[nodiscard]] Replaced publish(Table next) COSMIC_EXCLUDES(mutex_) {
    auto node = std::make_shared<Node>(std::move(next));
    {
      PiLock lock(mutex_);
      node.swap(current_);
    }
    return Replaced(std::move(node));
  }

  // Waits until every Reading of the replaced table has ended, then gives the table back.
  static Table retire(Replaced replaced) {
    Node& node = *replaced.node_;
    // acquire: pairs with each Reading's release, so their use of the table happened before this.
    while (node.readers.load(std::memory_order_acquire) != 0) {
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    return std::move(node.table);
  }

  // The current table, for the control thread only (the one thread that publishes): no Reading is
  // needed by the thread that alone replaces it.
  const Table& current_for_publisher() const COSMIC_NO_THREAD_SAFETY_ANALYSIS { return current_->table; }

 private:
  mutable PiMutex mutex_;
  std::shared_ptr<Node> current_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace cosmic

// The metrics endpoint's connections: at most `capacity` at a time, each on a thread of its own,
// and a new connection at the cap closes the one idle longest (issue 22, 3b: 300 to 1,100 idle
// connections had blinded the endpoint and taken the process to RLIMIT_NOFILE).
//
// ConnectionRegistry knows every accepted socket and what it is doing: idle (waiting for a
// request's first byte), reading (a head has begun) or serving (answering). The accept thread
// takes a slot per connection; at the cap it shuts down (shutdown(2)) the connection that has
// been idle longest or whose head began longest ago (a slow-loris), passing over connections with
// input waiting (a scraper whose request is in flight) while there are others, and waits for its
// thread to give the slot back. Connections being answered are never evicted: their time is
// bounded by the write deadline. Descriptors are closed only after remove(), under the same lock
// as eviction, so an eviction never reaches a descriptor number that was closed and reused.
//
// ConnectionPool is the cpp-httplib TaskQueue of the endpoint: a slot per task, and at most
// `capacity` threads (started when needed, all named by `on_thread_start`), so every accepted
// connection is served at once.
//
// Threads: acquire_slot() on the accept thread; everything else from any thread.
#pragma once

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

namespace cosmicd {

enum class ConnectionState { idle, reading, serving };

class ConnectionRegistry {
 public:
  using Clock = std::chrono::steady_clock;
  // Called after an eviction, outside the lock, with the number of evictions so far.
  using EvictionListener = std::function<void(std::uint64_t evictions)>;

  explicit ConnectionRegistry(std::size_t capacity, EvictionListener on_eviction = nullptr)
      : capacity_(capacity), on_eviction_(std::move(on_eviction)) {}

  // A slot for a connection just accepted: at the cap, evicts and waits until a connection ends.
  // False once stop() was called (the caller closes the connection at once).
  bool acquire_slot();
  void release_slot();

  // A connection's thread: add() before serving (false once stopped), set() as it goes, remove()
  // before closing the descriptor.
  bool add(int fd);
  void set(int fd, ConnectionState state);
  void remove(int fd);

  // Shuts down every connection; acquire_slot() and add() refuse from now on.
  void stop();

  std::size_t capacity() const { return capacity_; }
  std::size_t live() const;
  std::uint64_t evictions() const;

 private:
  struct Entry {
    ConnectionState state = ConnectionState::idle;
    Clock::time_point since;
    bool evicted = false;
  };
  // Shuts down the best candidate; false when there is none or an eviction is still under way.
  bool evict_locked();

  const std::size_t capacity_;
  const EvictionListener on_eviction_;
  mutable std::mutex mutex_;
  std::condition_variable slot_freed_;
  std::map<int, Entry> connections_;
  std::size_t slots_ = 0;
  std::uint64_t evictions_ = 0;
  bool stopped_ = false;
};

class ConnectionPool final : public httplib::TaskQueue {
 public:
  ConnectionPool(ConnectionRegistry& registry, std::function<void()> on_thread_start)
      : registry_(registry), on_thread_start_(std::move(on_thread_start)) {}
  ~ConnectionPool() override { shutdown(); }
  ConnectionPool(const ConnectionPool&) = delete;
  ConnectionPool& operator=(const ConnectionPool&) = delete;

  void enqueue(std::function<void()> task) override;
  void shutdown() override;

 private:
  void work();

  ConnectionRegistry& registry_;
  const std::function<void()> on_thread_start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::thread> threads_;
  std::size_t waiting_ = 0;  // threads waiting for a task
  bool stopping_ = false;
};

}  // namespace cosmicd

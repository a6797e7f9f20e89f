#include "metrics_http_connections.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <utility>

namespace cosmicd {
namespace {

// How long the accept thread waits for an evicted connection before looking again (a connection
// that was being answered may have become idle meanwhile).
constexpr auto kEvictionRecheck = std::chrono::milliseconds(100);

bool input_waiting(int fd) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 0) > 0;
}

}  // namespace

bool ConnectionRegistry::acquire_slot() {
  std::unique_lock lock(mutex_);
  while (!stopped_ && slots_ >= capacity_) {
    if (evict_locked() && on_eviction_) {
      const std::uint64_t count = evictions_;
      lock.unlock();
      on_eviction_(count);
      lock.lock();
      continue;
    }
    slot_freed_.wait_for(lock, kEvictionRecheck);
  }
  if (stopped_) return false;
  ++slots_;
  return true;
}

void ConnectionRegistry::release_slot() {
  {
    std::lock_guard lock(mutex_);
    if (slots_ > 0) --slots_;
  }
  slot_freed_.notify_all();
}

bool ConnectionRegistry::add(int fd) {
  std::lock_guard lock(mutex_);
  if (stopped_) return false;
  connections_[fd] = Entry{ConnectionState::idle, Clock::now(), false};
  return true;
}

void ConnectionRegistry::set(int fd, ConnectionState state) {
  std::lock_guard lock(mutex_);
  const auto it = connections_.find(fd);
  if (it == connections_.end()) return;
  it->second.state = state;
  it->second.since = Clock::now();
}

void ConnectionRegistry::remove(int fd) {
  std::lock_guard lock(mutex_);
  connections_.erase(fd);
}

void ConnectionRegistry::stop() {
  {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    for (const auto& [fd, entry] : connections_) ::shutdown(fd, SHUT_RDWR);
  }
  slot_freed_.notify_all();
}

std::size_t ConnectionRegistry::live() const {
  std::lock_guard lock(mutex_);
  return connections_.size();
}

std::uint64_t ConnectionRegistry::evictions() const {
  std::lock_guard lock(mutex_);
  return evictions_;
}

bool ConnectionRegistry::evict_locked() {
  // The connection longest in its state, idle or reading a head; one with input waiting is about
  // to be served (a scraper whose request is in flight) and goes only when all others are.
  int victim = -1;
  std::pair<bool, Clock::time_point> best{};
  for (const auto& [fd, entry] : connections_) {
    if (entry.evicted) return false;  // its thread is on its way out: that frees the slot
    if (entry.state == ConnectionState::serving) continue;
    const std::pair<bool, Clock::time_point> rank{input_waiting(fd), entry.since};
    if (victim < 0 || rank < best) {
      best = rank;
      victim = fd;
    }
  }
  if (victim < 0) return false;
  connections_[victim].evicted = true;
  ::shutdown(victim, SHUT_RDWR);
  ++evictions_;
  return true;
}

void ConnectionPool::enqueue(std::function<void()> task) {
  if (!registry_.acquire_slot()) {
    task();  // stopping: the connection is closed at once (ConnectionRegistry::add refuses it)
    return;
  }
  {
    std::lock_guard lock(mutex_);
    tasks_.push_back([this, task = std::move(task)] {
      task();
      registry_.release_slot();
    });
    // Every slot has a thread: a task never waits behind a connection.
    if (tasks_.size() > waiting_ && threads_.size() < registry_.capacity()) threads_.emplace_back([this] { work(); });
  }
  wake_.notify_one();
}

void ConnectionPool::shutdown() {
  registry_.stop();
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    threads.swap(threads_);
  }
  wake_.notify_all();
  for (std::thread& thread : threads) thread.join();
}

void ConnectionPool::work() {
  if (on_thread_start_) on_thread_start_();
  std::unique_lock lock(mutex_);
  for (;;) {
    ++waiting_;
    wake_.wait(lock, [&] { return !tasks_.empty() || stopping_; });
    --waiting_;
    if (tasks_.empty()) return;  // stopping, nothing left
    std::function<void()> task = std::move(tasks_.front());
    tasks_.pop_front();
    lock.unlock();
    task();
    lock.lock();
  }
}

}  // namespace cosmicd

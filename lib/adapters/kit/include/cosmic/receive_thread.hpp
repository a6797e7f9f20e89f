// The thread an adapter reads its network on, and the eventfd that wakes it (Linux only): named
// and run as the sink's receive policy says (cosmic/thread_policy.hpp), ended by stop(), which
// joins it. Its loop polls wake_fd() beside its sockets and returns once stopping() is true.
//
// Threads: start() and stop() by the adapter's control thread; wake() by any thread (senders
// that queued work for the loop, stop()); stopping(), clear_wakes() by the loop. The eventfd
// stays open from the first start() to the destructor, so a sender's wake() racing with stop()
// never writes to a closed (or reused) descriptor.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>

#include "cosmic/log.hpp"
#include "cosmic/result.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {

class ReceiveThread {
 public:
  ReceiveThread() = default;
  ReceiveThread(const ReceiveThread&) = delete;
  ReceiveThread& operator=(const ReceiveThread&) = delete;
  ~ReceiveThread();

  // Opens the wake eventfd (once) and runs `loop` on a new thread under `policy`. What the policy
  // could not get is logged as a warning, after `log_prefix` ("segment NAME: "). Fails when the
  // eventfd or the thread cannot be had or the thread is running already.
  Result<void> start(ThreadPolicy policy, Logger& log, std::string log_prefix, std::function<void()> loop);
  // Asks the loop to end, wakes it and joins it. Nothing when not running.
  void stop();
  bool running() const noexcept { return thread_.joinable(); }

  // Makes the loop's poll on wake_fd() return. Any thread; nothing before the first start().
  void wake() const noexcept;
  // The loop, after poll found wake_fd() readable: takes the wake-ups counted so far.
  void clear_wakes() const noexcept;
  int wake_fd() const noexcept { return wake_fd_.load(std::memory_order_acquire); }
  bool stopping() const noexcept { return stopping_.load(std::memory_order_acquire); }

 private:
  std::atomic<int> wake_fd_{-1};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace cosmic

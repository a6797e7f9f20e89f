// The wake-up between the threads that push into an egress lane and the lane's own thread.
//
// std::atomic<T>::wait in libstdc++ 12 spins before it sleeps, calling sched_yield() four times:
// at 1000 HRT events/s that was 3.3 system calls per event on top of the futex wait and wake,
// each of them a kernel entry that a virtual machine prices at microseconds (cosmic_router_bench
// BM_HrtResidence under strace -c). This signal sleeps in FUTEX_WAIT at once and makes the
// FUTEX_WAKE call only while a waiter is registered, so an event to a busy lane costs no system
// call at all. Linux only, like the rest of the forwarding plane.
//
// Threads: notify() from any thread; wait() from one or more waiting threads. It carries no data:
// what was pushed is read under the lane's own mutex after the wait returns.
#pragma once

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstdint>

namespace cosmic {

class WakeSignal {
 public:
  // The value to pass to wait(): read it before checking for work, so a notify() between the
  // check and the wait is never lost.
  std::uint32_t current() const noexcept { return sequence_.load(std::memory_order_seq_cst); }

  void notify_one() noexcept { bump_and_wake(1); }
  void notify_all() noexcept { bump_and_wake(INT_MAX); }

  // Returns once the sequence differs from `seen`, or spuriously (the caller checks for work again).
  void wait(std::uint32_t seen) noexcept {
    // Registered before the sequence is compared: a notify() that bumps the sequence after this
    // compare sees the waiter and wakes it, and one before it makes FUTEX_WAIT return at once
    // (the kernel compares the word with `seen` atomically with going to sleep).
    waiters_.fetch_add(1, std::memory_order_seq_cst);
    if (sequence_.load(std::memory_order_seq_cst) == seen) {
      syscall(SYS_futex, word(), FUTEX_WAIT_PRIVATE, seen, nullptr, nullptr, 0);
    }
    waiters_.fetch_sub(1, std::memory_order_seq_cst);
  }

 private:
  void bump_and_wake(int count) noexcept {
    sequence_.fetch_add(1, std::memory_order_seq_cst);
    if (waiters_.load(std::memory_order_seq_cst) > 0) {
      syscall(SYS_futex, word(), FUTEX_WAKE_PRIVATE, count, nullptr, nullptr, 0);
    }
  }
  std::uint32_t* word() noexcept { return reinterpret_cast<std::uint32_t*>(&sequence_); }

  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t) &&
                    std::atomic<std::uint32_t>::is_always_lock_free,
                "a futex word is a plain 32-bit integer");
  std::atomic<std::uint32_t> sequence_{0};
  std::atomic<std::uint32_t> waiters_{0};
};

}  // namespace cosmic

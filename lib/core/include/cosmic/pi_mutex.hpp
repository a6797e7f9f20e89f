// A mutex with priority inheritance (PTHREAD_PRIO_INHERIT) for the forwarding path.
//
// The payload pool, the route table pointer, a lane's ring and a channel's policy state are
// shared by threads of different classes: an HRT lane at SCHED_FIFO 80 releases payloads into the
// pool a time-shared NRT ingress thread takes from. With a plain mutex, an NRT thread preempted
// inside its few-instruction critical section keeps the HRT thread waiting for as long as the
// scheduler leaves it off the CPU (milliseconds on a loaded machine): a lower class delaying a
// higher one. With priority inheritance the kernel runs the holder at the waiter's priority
// until it unlocks. Uncontended, it costs what a plain mutex costs (a user-space atomic).
//
// A capability for clang's thread safety analysis (cosmic/thread_annotations.hpp): take it with
// PiLock (cosmic::LockGuard), which the analysis sees, not std::lock_guard, which it does not.
#pragma once

#include <pthread.h>

#include "cosmic/mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

class COSMIC_CAPABILITY("mutex") PiMutex {
 public:
  PiMutex() noexcept {
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    // Linux supports the protocol; where it would not, the mutex stays a plain one (still correct).
    pthread_mutexattr_setprotocol(&attr, PTHREAD_PRIO_INHERIT);
    pthread_mutex_init(&mutex_, &attr);
    pthread_mutexattr_destroy(&attr);
  }
  ~PiMutex() { pthread_mutex_destroy(&mutex_); }
  PiMutex(const PiMutex&) = delete;
  PiMutex& operator=(const PiMutex&) = delete;

  // Locking a valid, initialised, non-recursive mutex that this thread does not hold cannot fail
  // (EDEADLK/EINVAL are programming errors), so the results are not checked on the hot path.
  // Escape: the bodies call the unannotated pthread functions; they are what the analysis trusts.
  void lock() noexcept COSMIC_ACQUIRE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { pthread_mutex_lock(&mutex_); }
  bool try_lock() noexcept COSMIC_TRY_ACQUIRE(true) COSMIC_NO_THREAD_SAFETY_ANALYSIS {
    return pthread_mutex_trylock(&mutex_) == 0;
  }
  void unlock() noexcept COSMIC_RELEASE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { pthread_mutex_unlock(&mutex_); }

 private:
  pthread_mutex_t mutex_;
};

// The scoped lock of a PiMutex: `PiLock lock(mutex_);`.
using PiLock = LockGuard<PiMutex>;

}  // namespace cosmic

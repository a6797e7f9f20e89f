// Mutexes and scoped locks that clang's thread safety analysis can see (cosmic/thread_annotations.hpp).
//
// Mutex and SharedMutex are std::mutex and std::shared_mutex with the annotations libstdc++ does
// not carry; LockGuard, UniqueLock and SharedLock are the scoped locks to take them (and PiMutex,
// cosmic/pi_mutex.hpp) with. They cost what the std types cost: every call is inlined to the std
// one. Use them for every mutex whose state is annotated COSMIC_GUARDED_BY.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <shared_mutex>

#include "cosmic/thread_annotations.hpp"

namespace cosmic {

class UniqueLock;

class COSMIC_CAPABILITY("mutex") Mutex {
 public:
  Mutex() = default;
  Mutex(const Mutex&) = delete;
  Mutex& operator=(const Mutex&) = delete;

  // Escape: the bodies call the unannotated std::mutex; these are the primitives the analysis trusts.
  void lock() COSMIC_ACQUIRE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.lock(); }
  bool try_lock() COSMIC_TRY_ACQUIRE(true) COSMIC_NO_THREAD_SAFETY_ANALYSIS { return mutex_.try_lock(); }
  void unlock() COSMIC_RELEASE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.unlock(); }
  // Tells the analysis that this thread holds the mutex, taken by a caller further up the stack
  // (std::mutex cannot check it: nothing happens at run time). Say at each use why it is held.
  void assert_held() const COSMIC_ASSERT_CAPABILITY(this) {}

 private:
  friend class UniqueLock;  // waits on a std::condition_variable, which needs the std::mutex
  std::mutex mutex_;
};

class COSMIC_CAPABILITY("mutex") SharedMutex {
 public:
  SharedMutex() = default;
  SharedMutex(const SharedMutex&) = delete;
  SharedMutex& operator=(const SharedMutex&) = delete;

  // Escape: as Mutex's, the bodies call the unannotated std::shared_mutex.
  void lock() COSMIC_ACQUIRE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.lock(); }
  void unlock() COSMIC_RELEASE() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.unlock(); }
  void lock_shared() COSMIC_ACQUIRE_SHARED() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.lock_shared(); }
  void unlock_shared() COSMIC_RELEASE_SHARED() COSMIC_NO_THREAD_SAFETY_ANALYSIS { mutex_.unlock_shared(); }

 private:
  std::shared_mutex mutex_;
};

// std::lock_guard for any of cosmic's mutexes: `LockGuard lock(mutex_);`.
template <class M>
class COSMIC_SCOPED_CAPABILITY LockGuard {
 public:
  explicit LockGuard(M& mutex) COSMIC_ACQUIRE(mutex) : mutex_(mutex) { mutex_.lock(); }
  ~LockGuard() COSMIC_RELEASE() { mutex_.unlock(); }
  LockGuard(const LockGuard&) = delete;
  LockGuard& operator=(const LockGuard&) = delete;

 private:
  M& mutex_;
};

// std::unique_lock<std::mutex> for a Mutex: may be unlocked and locked again within its scope,
// and waits on a std::condition_variable. While wait() blocks the mutex is free, but it is held
// again when wait() returns, so to the analysis it stays held throughout: write the waits as
// `while (!condition) lock.wait(cv);` (a predicate lambda is a function of its own, which the
// analysis cannot know runs with the lock held).
class COSMIC_SCOPED_CAPABILITY UniqueLock {
 public:
  explicit UniqueLock(Mutex& mutex) COSMIC_ACQUIRE(mutex) : lock_(mutex.mutex_) {}
  ~UniqueLock() COSMIC_RELEASE() {}
  UniqueLock(const UniqueLock&) = delete;
  UniqueLock& operator=(const UniqueLock&) = delete;

  void lock() COSMIC_ACQUIRE() { lock_.lock(); }
  void unlock() COSMIC_RELEASE() { lock_.unlock(); }

  void wait(std::condition_variable& cv) { cv.wait(lock_); }
  template <class Clock, class Duration>
  std::cv_status wait_until(std::condition_variable& cv, const std::chrono::time_point<Clock, Duration>& deadline) {
    return cv.wait_until(lock_, deadline);
  }
  template <class Rep, class Period>
  std::cv_status wait_for(std::condition_variable& cv, const std::chrono::duration<Rep, Period>& timeout) {
    return cv.wait_for(lock_, timeout);
  }

 private:
  std::unique_lock<std::mutex> lock_;
};

// std::shared_lock for a SharedMutex: `SharedLock lock(table_mutex_);` reads.
class COSMIC_SCOPED_CAPABILITY SharedLock {
 public:
  explicit SharedLock(SharedMutex& mutex) COSMIC_ACQUIRE_SHARED(mutex) : mutex_(mutex) { mutex_.lock_shared(); }
  ~SharedLock() COSMIC_RELEASE() { mutex_.unlock_shared(); }
  SharedLock(const SharedLock&) = delete;
  SharedLock& operator=(const SharedLock&) = delete;

 private:
  SharedMutex& mutex_;
};

}  // namespace cosmic

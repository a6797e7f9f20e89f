// ThreadSanitizer builds only (COSMIC_TSAN): makes the locks Fast DDS takes with a timeout visible
// to ThreadSanitizer.
//
// libfastrtps locks its std::timed_mutex / std::recursive_timed_mutex with try_lock_until() and
// try_lock_for(), which libstdc++ implements with pthread_mutex_clocklock(CLOCK_MONOTONIC). The
// ThreadSanitizer runtime of GCC 12 (and LLVM, see llvm-project issue 62623) has no interceptor
// for pthread_mutex_clocklock: it sees the unlock but never the lock. It then reports "unlock of
// an unlocked mutex" inside libfastrtps (Fast-DDS issue 3222), misses the happens-before edges
// those mutexes give (spurious data races in Fast DDS's shared-memory transport) and builds a
// wrong lock-order graph (a spurious cycle through our reader listener's mutex).
//
// This definition, linked into every executable that links the DDS adapter in a TSan build,
// interposes glibc's: the executable comes first in the dynamic linker's lookup order, so
// libfastrtps's calls land here. It takes the same mutex with pthread_mutex_timedlock, which the
// ThreadSanitizer runtime does intercept, with the same deadline moved to CLOCK_REALTIME.
// Never part of a normal build.
#define _GNU_SOURCE
#include <pthread.h>
#include <time.h>

int pthread_mutex_clocklock(pthread_mutex_t* restrict mutex, clockid_t clock_id,
                            const struct timespec* restrict abstime) {
  if (clock_id == CLOCK_REALTIME) {
    return pthread_mutex_timedlock(mutex, abstime);
  }
  struct timespec now_on_clock;
  struct timespec now_realtime;
  clock_gettime(clock_id, &now_on_clock);
  clock_gettime(CLOCK_REALTIME, &now_realtime);
  const long long kNs = 1000000000LL;
  long long remaining =
      (long long)(abstime->tv_sec - now_on_clock.tv_sec) * kNs + (abstime->tv_nsec - now_on_clock.tv_nsec);
  if (remaining < 0) {
    remaining = 0;
  }
  const long long deadline = (long long)now_realtime.tv_sec * kNs + now_realtime.tv_nsec + remaining;
  const struct timespec realtime_deadline = {.tv_sec = deadline / kNs, .tv_nsec = deadline % kNs};
  return pthread_mutex_timedlock(mutex, &realtime_deadline);
}

// Clang's thread safety analysis (-Wthread-safety): annotations that say which mutex guards which
// state and which functions expect it held, checked at compile time by the clang build of
// scripts/test (CMake option COSMIC_THREAD_SAFETY; README.md, "Thread-safety analysis").
// Under any other compiler (the normal gcc build) every macro expands to nothing.
//
// The mutexes the analysis can see are cosmic's own: PiMutex (cosmic/pi_mutex.hpp, the forwarding
// path) and Mutex / SharedMutex (cosmic/mutex.hpp, wrappers of the std ones), each taken through
// cosmic's scoped locks (LockGuard, UniqueLock, SharedLock). libstdc++'s std::lock_guard and
// std::unique_lock carry no annotations: a member guarded by a mutex taken through them reads to
// the analysis as unguarded, so annotated state is always locked through cosmic's types.
//
// The escape, COSMIC_NO_THREAD_SAFETY_ANALYSIS, turns the analysis off for one function. Each use
// says why next to it; the kinds of use are:
//   - the bodies of the lock wrappers themselves (cosmic/mutex.hpp, pi_mutex.hpp), which call the
//     unannotated std or pthread primitives: they are what the analysis takes on trust;
//   - a function that releases and retakes a lock it was handed by reference (the CAN adapter's
//     send_afp): the analysis cannot tell which mutex that lock holds;
//   - a member that one thread alone writes (under its mutex), read by that thread without it
//     (CanAdapter::receive_socket): correct, but not a lock the analysis can see;
//   - code still taking its lock through std::lock_guard (Router::admit), and a known race left
//     for a decision (cosmic_last_error in libcosmic-client): both say so where they are.
// Narrower than the escape is Mutex::assert_held() (COSMIC_ASSERT_CAPABILITY): one statement
// saying "this thread holds it", where the lock was taken further up the call stack.
#pragma once

#if defined(__clang__)
#define COSMIC_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define COSMIC_THREAD_ANNOTATION(x)
#endif

// A type that is a lock (a mutex): `class COSMIC_CAPABILITY("mutex") Mutex`.
#define COSMIC_CAPABILITY(name) COSMIC_THREAD_ANNOTATION(capability(name))
// An RAII type that holds a capability for its lifetime (LockGuard).
#define COSMIC_SCOPED_CAPABILITY COSMIC_THREAD_ANNOTATION(scoped_lockable)
// A data member read and written only with the mutex held (shared for reads, exclusive for writes).
#define COSMIC_GUARDED_BY(mutex) COSMIC_THREAD_ANNOTATION(guarded_by(mutex))
// A pointer member whose pointee is guarded by the mutex (the pointer itself is not).
#define COSMIC_PT_GUARDED_BY(mutex) COSMIC_THREAD_ANNOTATION(pt_guarded_by(mutex))
// The caller must hold the mutex (exclusively / at least shared).
#define COSMIC_REQUIRES(...) COSMIC_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define COSMIC_REQUIRES_SHARED(...) COSMIC_THREAD_ANNOTATION(requires_shared_capability(__VA_ARGS__))
// The function takes the mutex and returns holding it / releases one the caller held.
#define COSMIC_ACQUIRE(...) COSMIC_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define COSMIC_ACQUIRE_SHARED(...) COSMIC_THREAD_ANNOTATION(acquire_shared_capability(__VA_ARGS__))
#define COSMIC_RELEASE(...) COSMIC_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define COSMIC_RELEASE_SHARED(...) COSMIC_THREAD_ANNOTATION(release_shared_capability(__VA_ARGS__))
// Releases the capability whether it is held exclusively or shared (a scoped lock's destructor).
#define COSMIC_RELEASE_GENERIC(...) COSMIC_THREAD_ANNOTATION(release_generic_capability(__VA_ARGS__))
// try_lock(): holds the mutex afterwards exactly when it returned `result`.
#define COSMIC_TRY_ACQUIRE(...) COSMIC_THREAD_ANNOTATION(try_acquire_capability(__VA_ARGS__))
// The caller must not hold the mutex (the function takes it itself; holding it would deadlock).
#define COSMIC_EXCLUDES(...) COSMIC_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))
// The function returns only if the calling thread holds the mutex: from there on the analysis
// takes it as held (Mutex::assert_held(), for a lock a caller further up is known to hold).
#define COSMIC_ASSERT_CAPABILITY(x) COSMIC_THREAD_ANNOTATION(assert_capability(x))
// A function returning a reference to the mutex (lets callers name it in other annotations).
#define COSMIC_RETURN_CAPABILITY(x) COSMIC_THREAD_ANNOTATION(lock_returned(x))
// The escape: no analysis inside this function. Say why wherever it is used.
#define COSMIC_NO_THREAD_SAFETY_ANALYSIS COSMIC_THREAD_ANNOTATION(no_thread_safety_analysis)

// cosmicd answers syscall(SYS_gettid) from a per-thread cache, for every library in the process.
//
// Why: Debian builds Fast DDS 2.9 without NDEBUG, so the assertions of its reliable reader stay
// compiled in, and each asks the kernel for the calling thread's id (WriterProxy::get_thread_id
// is `syscall(__NR_gettid)`) several times for every sample and every heartbeat it processes.
// Forwarding DDS -> LCM at saturation that was 17.6 system calls per event, 1.19 million of
// cosmicd's 1.27 million (perf stat); answered from here, cosmicd's receive thread took about
// 40% more events per CPU second. A thread's id never changes, so its first answer is kept.
//
// How: the executable defines `syscall`, and the dynamic linker binds every library's calls of it
// to the executable's definition, which comes first in symbol lookup (the link exports it, see
// daemon/CMakeLists.txt). Every other system call number goes on to the C library's syscall()
// with six arguments: that is what that function hands the kernel whatever its caller passed
// (reading the ones a caller did not pass is what the x86-64 and AArch64 calling conventions
// make harmless, and what glibc's own syscall() does). glibc makes its own system calls inline,
// never through this symbol.
//
// Children: fork() clears the forking thread's cache in the child (pthread_atfork), and so does
// a fork or clone made through syscall() itself that gives the child its own memory. A child
// that shares the parent's memory (vfork, CLONE_VM) shares its thread-local storage too: it is
// left alone, and such a child must only exec or exit, as vfork requires anyway.
//
// No lock and no function-local static here: libstdc++ waits for a static's initialization with
// syscall(SYS_futex), which would come back here.
#include <dlfcn.h>
#include <pthread.h>
#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstdlib>

namespace {

using SyscallFunction = long (*)(long, ...);

std::atomic<SyscallFunction> c_library_syscall{nullptr};
thread_local long cached_thread_id = 0;  // 0: not asked yet (no thread has id 0)

SyscallFunction resolve_c_library_syscall() {
  const int saved_errno = errno;
  auto* function = reinterpret_cast<SyscallFunction>(::dlsym(RTLD_NEXT, "syscall"));
  errno = saved_errno;
  if (function == nullptr) std::abort();  // a C library without syscall(): nothing can run
  c_library_syscall.store(function, std::memory_order_release);
  return function;
}

// Resolved when cosmicd is loaded (below); a library constructor that calls syscall() before
// that resolves it itself (racing callers store the same address).
SyscallFunction real_syscall() {
  SyscallFunction function = c_library_syscall.load(std::memory_order_acquire);
  return function != nullptr ? function : resolve_c_library_syscall();
}

void forget_thread_id() { cached_thread_id = 0; }

// A child of a fork or clone made through syscall(): does it have memory of its own?
bool child_has_own_memory(long number, long first_argument) {
#ifdef SYS_fork  // x86-64; AArch64 has clone alone
  if (number == SYS_fork) return true;
#endif
  // vfork shares the memory; clone3's flags sit in a structure: both left alone.
  return number == SYS_clone && (static_cast<unsigned long>(first_argument) & CLONE_VM) == 0;
}

[[maybe_unused]] const bool loaded = [] {
  resolve_c_library_syscall();
  ::pthread_atfork(nullptr, nullptr, &forget_thread_id);
  return true;
}();

}  // namespace

extern "C" long syscall(long number, ...) {
  if (number == SYS_gettid) {
    if (cached_thread_id > 0) return cached_thread_id;
    const long id = real_syscall()(SYS_gettid);
    if (id > 0) cached_thread_id = id;  // never a refusal (a seccomp filter may answer -1)
    return id;
  }
  std::va_list arguments;
  va_start(arguments, number);
  const long a = va_arg(arguments, long);
  const long b = va_arg(arguments, long);
  const long c = va_arg(arguments, long);
  const long d = va_arg(arguments, long);
  const long e = va_arg(arguments, long);
  const long f = va_arg(arguments, long);
  va_end(arguments);
  const long result = real_syscall()(number, a, b, c, d, e, f);
  if (result == 0 && child_has_own_memory(number, a)) forget_thread_id();
  return result;
}

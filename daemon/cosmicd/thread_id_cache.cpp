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
// with six argument registers: that is what that function hands the kernel whatever its caller
// passed, and reading the unused ones costs nothing.
//
// A forked child starts with its parent thread's cache; pthread_atfork clears it there. No
// lock and no function-local static here: libstdc++ waits for a static's initialization with
// syscall(SYS_futex), which would come back here.
#include <dlfcn.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdarg>
#include <cstdlib>

namespace {

using SyscallFunction = long (*)(long, ...);

std::atomic<SyscallFunction> c_library_syscall{nullptr};
thread_local long cached_thread_id = 0;  // 0: not asked yet (no thread has id 0)

SyscallFunction real_syscall() {
  SyscallFunction function = c_library_syscall.load(std::memory_order_acquire);
  if (function == nullptr) {
    // Racing first callers resolve the same address; each stores it.
    function = reinterpret_cast<SyscallFunction>(::dlsym(RTLD_NEXT, "syscall"));
    if (function == nullptr) std::abort();  // a C library without syscall(): nothing can run
    c_library_syscall.store(function, std::memory_order_release);
  }
  return function;
}

void forget_thread_id_in_child() { cached_thread_id = 0; }

// Registered when cosmicd is loaded, before main().
[[maybe_unused]] const int fork_guard = ::pthread_atfork(nullptr, nullptr, &forget_thread_id_in_child);

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
  return real_syscall()(number, a, b, c, d, e, f);
}

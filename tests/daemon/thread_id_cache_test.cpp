// cosmicd's syscall(): gettid from a per-thread cache (daemon/cosmicd/thread_id_cache.cpp), every
// other system call passed through. This test binary links the same file and exports the symbol
// as cosmicd does.
#include <dlfcn.h>
#include <fcntl.h>
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <climits>
#include <cstddef>
#include <string>
#include <thread>
#include <vector>

extern "C" long thread_id_probe_gettid();  // thread_id_probe.cpp, a shared library

namespace {

// The calling thread's id as the kernel names it in /proc, without any system call number.
long thread_id_from_proc() {
  char target[PATH_MAX] = {};
  const ssize_t n = ::readlink("/proc/thread-self", target, sizeof target - 1);
  if (n <= 0) return -1;
  const std::string path(target, static_cast<std::size_t>(n));  // "<pid>/task/<tid>"
  return std::stol(path.substr(path.rfind('/') + 1));
}

TEST(ThreadIdCache, EveryLibraryBindsToThisSyscall) {
  EXPECT_EQ(::dlsym(RTLD_DEFAULT, "syscall"), reinterpret_cast<void*>(&::syscall));
}

TEST(ThreadIdCache, EachThreadGetsItsOwnId) {
  EXPECT_EQ(::syscall(SYS_gettid), thread_id_from_proc());
  EXPECT_EQ(::syscall(SYS_gettid), ::syscall(SYS_gettid));
  constexpr int kThreads = 4;
  std::vector<long> cached(kThreads), from_proc(kThreads);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      cached[i] = ::syscall(SYS_gettid);
      from_proc[i] = thread_id_from_proc();
      if (::syscall(SYS_gettid) != cached[i]) cached[i] = -1;
    });
  }
  for (auto& t : threads) t.join();
  for (int i = 0; i < kThreads; ++i) {
    EXPECT_EQ(cached[i], from_proc[i]) << "thread " << i;
    EXPECT_NE(cached[i], ::syscall(SYS_gettid)) << "thread " << i;
  }
  // A thread on a stack (and thread-local storage) glibc reuses from one that ended.
  long reused = 0, reused_from_proc = -1;
  std::thread([&] {
    reused = ::syscall(SYS_gettid);
    reused_from_proc = thread_id_from_proc();
  }).join();
  EXPECT_EQ(reused, reused_from_proc);
}

TEST(ThreadIdCache, OtherSystemCallsPassThroughWithTheirArgumentsAndErrors) {
  EXPECT_EQ(::syscall(SYS_getpid), static_cast<long>(::getpid()));
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const char sent[] = "abc";
  EXPECT_EQ(::syscall(SYS_write, fds[1], sent, 3), 3);
  char got[4] = {};
  EXPECT_EQ(::syscall(SYS_read, fds[0], got, 3), 3);
  EXPECT_STREQ(got, "abc");
  ::close(fds[0]);
  ::close(fds[1]);
  // Arguments beyond the third reach the kernel too: pread64's offset is its fourth.
  const int file = ::memfd_create("thread-id-cache-test", 0);
  ASSERT_GE(file, 0);
  ASSERT_EQ(::write(file, "0123456789", 10), 10);
  char at_six[3] = {};
  EXPECT_EQ(::syscall(SYS_pread64, file, at_six, 2, 6L), 2);
  EXPECT_STREQ(at_six, "67");
  ::close(file);
  errno = 0;
  EXPECT_EQ(::syscall(SYS_close, -1), -1);
  EXPECT_EQ(errno, EBADF);
}

// A forbidden gettid: the kernel answers EPERM from here on, so an answer that is still right
// came from the cache. A thread that never asked before gets the kernel's refusal, which shows
// the filter works. Runs in a child, which also shows the cache follows a fork.
int child_after_forbidding_gettid() {
  if (::syscall(SYS_gettid) != ::getpid()) return 10;  // the forking thread's cache was cleared
  sock_filter program[] = {
      BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)),
      BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, SYS_gettid, 0, 1),
      BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ERRNO | (EPERM & SECCOMP_RET_DATA)),
      BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
  };
  sock_fprog filter{static_cast<unsigned short>(sizeof program / sizeof program[0]), program};
  if (::prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) return 11;
  if (::prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &filter) != 0) return 12;
  if (::syscall(SYS_gettid) != ::getpid()) return 13;     // cached: no system call made
  if (thread_id_probe_gettid() != ::getpid()) return 15;  // a library's versioned call: the same
  long fresh = 0;
  std::thread other([&] { fresh = ::syscall(SYS_gettid); });
  other.join();
  if (fresh != -1) return 14;  // the filter did not refuse: the check above proved nothing
  return 0;
}

TEST(ThreadIdCache, AnswersWithoutAskingTheKernelAgainAndIsClearedInAForkedChild) {
  ASSERT_GT(::syscall(SYS_gettid), 0);  // the parent's cache filled before the fork
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(child_after_forbidding_gettid());
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: fork kept the parent's id, 11/12: no seccomp here, "
                                       "13: asked the kernel again, 14: the filter refused nothing, "
                                       "15: a shared library's syscall() is not this one";
}

#ifdef SYS_fork
// A fork made through syscall() itself, as a library could, skips pthread_atfork: the wrapper
// clears the cache in the child. The child makes system calls only, then _exit.
TEST(ThreadIdCache, IsClearedInTheChildOfAForkMadeThroughSyscall) {
  ASSERT_GT(::syscall(SYS_gettid), 0);
  const long child = ::syscall(SYS_fork);
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(::syscall(SYS_gettid) == ::syscall(SYS_getpid) ? 0 : 1);
  int status = 0;
  ASSERT_EQ(::waitpid(static_cast<pid_t>(child), &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the child answered with its parent's thread id";
}
#endif

}  // namespace

// A shared library that asks for the thread id the way Fast DDS does (`syscall(__NR_gettid)`,
// bound to glibc's versioned `syscall@GLIBC_2.2.5`): thread_id_cache_test.cpp checks that such a
// call reaches the executable's cache.
#include <sys/syscall.h>
#include <unistd.h>

extern "C" long thread_id_probe_gettid() { return ::syscall(__NR_gettid); }

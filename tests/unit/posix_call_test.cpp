// The result vocabulary (cosmic/result.hpp) and the checked system call of the adapters' kit
// (cosmic/posix_call.hpp).
#include "cosmic/posix_call.hpp"

#include <fcntl.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>

#include <gtest/gtest.h>

namespace cosmic {
namespace {

TEST(PosixCall, ReturnsWhatTheCallReturned) {
  auto fd = posix_call("eventfd", [] { return ::eventfd(0, EFD_CLOEXEC); });
  ASSERT_TRUE(fd.ok()) << fd.error().text;
  OwnedFd owned(fd.value());
  EXPECT_GE(owned.get(), 0);
}

TEST(PosixCall, AFailureKeepsErrnoAndSaysWhatFailed) {
  auto opened = posix_call("open /nonexistent/x", [] { return ::open("/nonexistent/x", O_RDONLY | O_CLOEXEC); });
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error().code, ENOENT);
  EXPECT_EQ(opened.error().text, "open /nonexistent/x: No such file or directory");
  EXPECT_EQ(opened.error().channel, kNoChannel);
}

TEST(PosixCall, RetriesWhileInterrupted) {
  int calls = 0;
  auto result = posix_call("flaky", [&] {
    if (++calls < 3) {
      errno = EINTR;
      return -1;
    }
    return 7;
  });
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result.value(), 7);
  EXPECT_EQ(calls, 3);
}

TEST(PosixCall, TheErrorTextIsTheKernelsForThatErrno) {
  EXPECT_EQ(errno_text(EAGAIN), "Resource temporarily unavailable");
  EXPECT_EQ(Error::from_errno("write to can0", ENOBUFS).text, "write to can0: No buffer space available");
}

TEST(Result, CarriesAValueOrAnError) {
  Result<std::string> good(std::string("bound"));
  EXPECT_TRUE(good);
  EXPECT_EQ(good.value(), "bound");
  Result<std::string> bad(Error{"channel speed: no writer", 0, 4});
  EXPECT_FALSE(bad);
  EXPECT_EQ(bad.value_or("none"), "none");
  EXPECT_EQ(bad.error().channel, 4u);
  Result<void> done;
  EXPECT_TRUE(done.ok());
  Result<void> failed(Error{"not started"});
  EXPECT_EQ(failed.error().text, "not started");
}

TEST(OwnedFd, ClosesWhatItOwnsAndNothingItReleased) {
  int raw = ::eventfd(0, EFD_CLOEXEC);
  ASSERT_GE(raw, 0);
  {
    OwnedFd owned(raw);
    OwnedFd moved(std::move(owned));
    EXPECT_EQ(owned.get(), -1);
    EXPECT_EQ(moved.get(), raw);
  }
  EXPECT_EQ(::fcntl(raw, F_GETFD), -1) << "closed with its owner";
  EXPECT_EQ(errno, EBADF);
  int kept = ::eventfd(0, EFD_CLOEXEC);
  {
    OwnedFd owned(kept);
    EXPECT_EQ(owned.release(), kept);
  }
  EXPECT_NE(::fcntl(kept, F_GETFD), -1) << "released: still open";
  ::close(kept);
}

}  // namespace
}  // namespace cosmic

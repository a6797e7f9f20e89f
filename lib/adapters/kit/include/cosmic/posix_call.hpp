// A system call checked once, the same way everywhere (after iceoryx's IOX_POSIX_CALL): retried
// while it fails with EINTR; a failure becomes an Error "WHAT: <errno text>" with errno kept in
// Error::code, and the text is built only then. Linux only.
//
// Threads: any; no state of its own.
#pragma once

#include <cerrno>
#include <string_view>
#include <type_traits>
#include <utility>

#include "cosmic/result.hpp"

namespace cosmic {

// Calls `call()` (a system call returning -1 with errno on failure, as most do) until it returns
// something else or fails with an error other than EINTR.
template <typename Call>
Result<std::invoke_result_t<Call>> posix_call(std::string_view what, Call&& call) {
  for (;;) {
    const auto returned = call();
    if (returned != -1) return returned;
    const int err = errno;
    if (err != EINTR) return Error::from_errno(what, err);
  }
}

// A file descriptor that closes itself: what posix_call opened stays owned until released.
class OwnedFd {
 public:
  OwnedFd() = default;
  explicit OwnedFd(int fd) noexcept : fd_(fd) {}
  OwnedFd(OwnedFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  OwnedFd& operator=(OwnedFd&& other) noexcept {
    if (this != &other) reset(std::exchange(other.fd_, -1));
    return *this;
  }
  OwnedFd(const OwnedFd&) = delete;
  OwnedFd& operator=(const OwnedFd&) = delete;
  ~OwnedFd() { reset(); }

  int get() const noexcept { return fd_; }
  int release() noexcept { return std::exchange(fd_, -1); }
  void reset(int fd = -1) noexcept;

 private:
  int fd_ = -1;
};

}  // namespace cosmic

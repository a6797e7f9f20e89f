#include "cosmic/receive_thread.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <cstdint>
#include <exception>

#include "cosmic/posix_call.hpp"

namespace cosmic {

Result<void> ReceiveThread::start(ThreadPolicy policy, Logger& log, std::string log_prefix,
                                  std::function<void()> loop) {
  if (running()) return Error{"the receive thread is running already"};
  if (wake_fd() < 0) {
    auto fd = posix_call("eventfd for the receive thread", [] { return ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC); });
    if (!fd) return std::move(fd).error();
    wake_fd_.store(fd.value(), std::memory_order_release);
  }
  clear_wakes();  // what was asked of an earlier loop is not this one's
  stopping_.store(false, std::memory_order_release);
  try {
    thread_ = std::thread([&log, policy = std::move(policy), prefix = std::move(log_prefix), loop = std::move(loop)] {
      for (const auto& problem : apply_thread_policy(policy))
        log.log(LogLevel::warning, prefix + "receive thread: " + problem);
      loop();
    });
  } catch (const std::exception& e) {
    return Error{std::string("cannot start the receive thread: ") + e.what()};
  }
  return {};
}

void ReceiveThread::stop() {
  if (!thread_.joinable()) return;
  stopping_.store(true, std::memory_order_release);
  wake();
  thread_.join();
}

ReceiveThread::~ReceiveThread() {
  stop();
  if (const int fd = wake_fd_.exchange(-1); fd >= 0) ::close(fd);
}

void ReceiveThread::wake() const noexcept {
  const int fd = wake_fd();
  if (fd < 0) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(fd, &one, sizeof one);
}

void ReceiveThread::clear_wakes() const noexcept {
  std::uint64_t count = 0;
  [[maybe_unused]] const ssize_t n = ::read(wake_fd(), &count, sizeof count);
}

}  // namespace cosmic

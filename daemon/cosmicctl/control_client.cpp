#include "control_client.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace cosmicctl {
namespace {

class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

ClientResult failure(std::string why, bool permission_denied = false) {
  return ClientResult{std::nullopt, std::move(why), permission_denied};
}

}  // namespace

ClientResult request(const std::string& socket_path, const nlohmann::json& request, int timeout_ms) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket_path.size() >= sizeof address.sun_path) return failure("socket path too long: " + socket_path);
  std::memcpy(address.sun_path, socket_path.c_str(), socket_path.size() + 1);
  Descriptor fd(::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (fd.get() < 0) return failure(std::string("socket: ") + std::strerror(errno));
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const bool denied = errno == EACCES || errno == EPERM;
    return failure("cannot reach cosmicd at " + socket_path + ": " + std::strerror(errno) +
                              (denied ? " (join the group that owns the socket, e.g. cosmic)" : ""),
            denied);
  }
  const std::string line = request.dump() + "\n";
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t n = ::send(fd.get(), line.data() + written, line.size() - written, MSG_NOSIGNAL);
    if (n <= 0) return failure(std::string("sending the request failed: ") + std::strerror(errno));
    written += static_cast<std::size_t>(n);
  }
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (answer.find('\n') == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return failure("cosmicd did not answer within " + std::to_string(timeout_ms / 1000) + " s");
    pollfd p{fd.get(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char buffer[65536];
    const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
    if (n <= 0) return failure("cosmicd closed the connection without an answer");
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  auto parsed = nlohmann::json::parse(answer.substr(0, answer.find('\n')), nullptr, false);
  if (parsed.is_discarded()) return failure("cosmicd sent an unreadable answer");
  return ClientResult{std::move(parsed), {}, false};
}

}  // namespace cosmicctl

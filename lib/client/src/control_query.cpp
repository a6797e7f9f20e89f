#include "control_query.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "cosmic/client.h"

namespace cosmic::client_detail {
namespace {

constexpr int kTimeoutMs = 5000;

// One JSON line out, one back; empty with `error` set on failure.
std::string exchange(const std::string& socket_path, const std::string& line, std::string& error) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket_path.size() >= sizeof address.sun_path) {
    error = "socket path too long";
    return {};
  }
  std::memcpy(address.sun_path, socket_path.c_str(), socket_path.size());
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  std::string reply;
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::send(fd, line.data(), line.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(line.size())) {
    error = socket_path + ": " + std::strerror(errno);
  } else {
    pollfd p{fd, POLLIN, 0};
    char buffer[4096];
    while (reply.find('\n') == std::string::npos && ::poll(&p, 1, kTimeoutMs) == 1) {
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      reply.append(buffer, static_cast<std::size_t>(n));
    }
    if (reply.find('\n') == std::string::npos) error = "no answer from " + socket_path;
  }
  if (fd >= 0) ::close(fd);
  return error.empty() ? reply : std::string();
}

}  // namespace

int query_verdict(const std::string& socket_path, const std::string& name, std::string& out) {
  const nlohmann::json request{{"command", "channel"}, {"name", name}};
  const std::string reply = exchange(socket_path, request.dump() + "\n", out);
  if (reply.empty()) return COSMIC_E_UNAVAILABLE;
  const auto answer = nlohmann::json::parse(reply, nullptr, false);
  if (answer.is_discarded() || !answer.is_object()) {
    out = "not a control protocol answer";
    return COSMIC_E_UNAVAILABLE;
  }
  if (answer.value("ok", false)) {
    out = answer["channel"].value("verdict", "bound");
    return COSMIC_OK;
  }
  const auto error = answer.value("error", nlohmann::json::object());
  const std::string code = error.value("code", "");
  if (code == "not_found") {
    out = "not_found";
    return COSMIC_OK;
  }
  if (code == "rejected") {  // a channel of the gateway's configuration that admission rejected
    std::string reasons;
    for (const auto& r : error.value("reasons", nlohmann::json::array())) {
      if (r.is_string()) reasons += (reasons.empty() ? "" : "; ") + r.get<std::string>();
    }
    out = "rejected (" + reasons + ")";
    return COSMIC_OK;
  }
  out = "refused: " + code;
  return COSMIC_E_UNAVAILABLE;
}

}  // namespace cosmic::client_detail

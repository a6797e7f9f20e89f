#include "control_client.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <iostream>

#include "commands.hpp"
#include "cosmic/posix_call.hpp"

namespace cosmicctl {
namespace {

ClientResult failure(std::string why, bool permission_denied = false) {
  return ClientResult{std::nullopt, std::move(why), permission_denied};
}

// Sends all of `line`; returns 0, or the errno that stopped it (the daemon may have answered
// and closed before reading everything: too_large, busy).
int send_all(int fd, const std::string& line) {
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t n = ::send(fd, line.data() + written, line.size() - written, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : EPIPE;
    written += static_cast<std::size_t>(n);
  }
  return 0;
}

// Reads up to the first newline. Empty `error` with an empty answer: the daemon closed first.
std::string read_line(int fd, int timeout_ms, std::string& error) {
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (answer.find('\n') == std::string::npos) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      error = "cosmicd did not answer within " + std::to_string(timeout_ms / 1000) + " s";
      return {};
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char buffer[65536];
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return {};
    answer.append(buffer, static_cast<std::size_t>(n));
  }
  return answer.substr(0, answer.find('\n'));
}

}  // namespace

std::optional<std::size_t> first_invalid_utf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto byte = static_cast<unsigned char>(text[i]);
    const std::size_t length = byte < 0x80           ? 1
                               : (byte >> 5) == 0x6  ? 2
                               : (byte >> 4) == 0xE  ? 3
                               : (byte >> 3) == 0x1E ? 4
                                                     : 0;
    if (length == 0 || i + length > text.size()) return i;
    for (std::size_t k = 1; k < length; ++k) {
      if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return i;
    }
    // Overlong forms, surrogates and code points above U+10FFFF are not UTF-8 either.
    const auto next = static_cast<unsigned char>(length > 1 ? text[i + 1] : 0);
    const bool overlong = (length == 2 && byte < 0xC2) || (length == 3 && byte == 0xE0 && next < 0xA0) ||
                          (length == 4 && byte == 0xF0 && next < 0x90);
    const bool out_of_range = (length == 3 && byte == 0xED && next >= 0xA0) ||
                              (length == 4 && (byte > 0xF4 || (byte == 0xF4 && next >= 0x90)));
    if (overlong || out_of_range) return i;
    i += length;
  }
  return std::nullopt;
}

ClientResult request(const std::string& socket_path, const nlohmann::json& request, int timeout_ms) {
  std::string line;
  try {
    line = request.dump() + "\n";
  } catch (const nlohmann::json::exception& e) {
    return failure(std::string("cannot encode the request: ") + e.what());
  }
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket_path.size() >= sizeof address.sun_path) return failure("socket path too long: " + socket_path);
  std::memcpy(address.sun_path, socket_path.c_str(), socket_path.size() + 1);
  auto opened = cosmic::posix_call("socket", [] { return ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0); });
  if (!opened) return failure(opened.error().text);
  const cosmic::OwnedFd fd(opened.value());
  if (::connect(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const bool denied = errno == EACCES || errno == EPERM;
    return failure("cannot reach cosmicd at " + socket_path + ": " + std::strerror(errno) +
                       (denied ? " (join the group that owns the socket, e.g. cosmic)" : ""),
                   denied);
  }
  const int send_error = send_all(fd.get(), line);
  std::string error;
  const std::string answer = read_line(fd.get(), timeout_ms, error);
  if (answer.empty()) {
    if (!error.empty()) return failure(error);
    if (send_error != 0) return failure(std::string("sending the request failed: ") + std::strerror(send_error));
    return failure("cosmicd closed the connection without an answer");
  }
  auto parsed = nlohmann::json::parse(answer, nullptr, false);
  if (parsed.is_discarded()) return failure("cosmicd sent an unreadable answer");
  return ClientResult{std::move(parsed), {}, false};
}

namespace {
std::string error_text(const nlohmann::json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}
}  // namespace

void print_errors(const nlohmann::json& response) {
  std::cerr << "cosmicctl: " << error_text(response["error"].value("message", nlohmann::json("request failed")))
            << "\n";
  if (response.contains("errors")) {
    for (const auto& e : response["errors"]) std::cerr << error_text(e["text"]) << "\n";
  }
}

int exit_code_for_failure(const nlohmann::json& response) {
  const std::string code = response["error"].value("code", "");
  if (code == "permission_denied") return kExitNoPermission;
  if (code == "config_error") return kExitConfigError;
  if (code == "bad_request" || code == "unknown_command") return kExitUsage;
  if (code == "busy" || code == "timeout") return kExitTempFail;
  return kExitRejected;
}

}  // namespace cosmicctl

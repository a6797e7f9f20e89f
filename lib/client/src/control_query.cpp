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
// The answer to one `channel` question is a few KiB; a gateway sending more is not trusted to end.
constexpr std::size_t kMaxAnswerBytes = 1u << 20;

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
    while (reply.find('\n') == std::string::npos && reply.size() <= kMaxAnswerBytes && ::poll(&p, 1, kTimeoutMs) == 1) {
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      reply.append(buffer, static_cast<std::size_t>(n));
    }
    if (reply.size() > kMaxAnswerBytes && reply.find('\n') == std::string::npos) {
      error = "answer from " + socket_path + " longer than " + std::to_string(kMaxAnswerBytes) + " bytes";
    } else if (reply.find('\n') == std::string::npos) {
      error = "no answer from " + socket_path;
    }
  }
  if (fd >= 0) ::close(fd);
  return error.empty() ? reply : std::string();
}

// The answer, read without trusting its shape: every member is checked for its type before use
// (nlohmann's value() and operator[] throw or assert on a wrong one), so a malformed answer is an
// error code, never an exception crossing the C API (issue 22, item 7).
int read_answer(const nlohmann::json& answer, std::string& out) {
  auto malformed = [&out](const char* what) {
    out = std::string("malformed control answer: ") + what;
    return COSMIC_E_UNAVAILABLE;
  };
  if (!answer.is_object()) return malformed("not a JSON object");
  const auto ok = answer.find("ok");
  if (ok == answer.end() || !ok->is_boolean()) return malformed("no boolean \"ok\"");
  if (ok->get<bool>()) {
    const auto channel = answer.find("channel");
    if (channel == answer.end() || !channel->is_object()) return malformed("no \"channel\" object");
    const auto verdict = channel->find("verdict");
    if (verdict == channel->end() || !verdict->is_string()) return malformed("no \"verdict\" string");
    out = verdict->get<std::string>();
    return COSMIC_OK;
  }
  const auto error = answer.find("error");
  if (error == answer.end() || !error->is_object()) return malformed("no \"error\" object");
  const auto code_member = error->find("code");
  if (code_member == error->end() || !code_member->is_string()) return malformed("no \"code\" string");
  const std::string code = code_member->get<std::string>();
  if (code == "not_found") {
    out = "not_found";
    return COSMIC_OK;
  }
  if (code == "rejected") {  // a channel of the gateway's configuration that admission rejected
    std::string reasons;
    if (const auto list = error->find("reasons"); list != error->end() && list->is_array()) {
      for (const auto& r : *list) {
        if (r.is_string()) reasons += (reasons.empty() ? "" : "; ") + r.get<std::string>();
      }
    }
    out = "rejected (" + reasons + ")";
    return COSMIC_OK;
  }
  out = "refused: " + code;
  return COSMIC_E_UNAVAILABLE;
}

}  // namespace

int query_verdict(const std::string& socket_path, const std::string& name, std::string& out) {
  try {
    const nlohmann::json request{{"command", "channel"}, {"name", name}};
    const std::string reply = exchange(socket_path, request.dump() + "\n", out);
    if (reply.empty()) return COSMIC_E_UNAVAILABLE;
    return parse_verdict_answer(reply, out);
  } catch (const std::exception& e) {  // out of memory, or a name that is not UTF-8 (dump throws)
    out = std::string("control query failed: ") + e.what();
    return COSMIC_E_UNAVAILABLE;
  }
}

int parse_verdict_answer(std::string_view reply, std::string& out) {
  try {
    const auto answer = nlohmann::json::parse(reply, nullptr, false);
    if (answer.is_discarded()) {
      out = "not a control protocol answer";
      return COSMIC_E_UNAVAILABLE;
    }
    return read_answer(answer, out);
  } catch (const std::exception& e) {
    out = std::string("control answer unreadable: ") + e.what();
    return COSMIC_E_UNAVAILABLE;
  }
}

}  // namespace cosmic::client_detail

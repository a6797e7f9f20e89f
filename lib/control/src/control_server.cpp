#include "cosmic/control_server.hpp"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace cosmic {
namespace {

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

bool someone_listens(const sockaddr_un& address) {
  const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (probe < 0) return false;
  const bool listening = ::connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  ::close(probe);
  return listening;
}

constexpr std::string_view kTooLarge =
    R"({"ok":false,"error":{"code":"too_large","message":"request larger than the limit; connection closed"}})"
    "\n";
constexpr std::string_view kBusy =
    R"({"ok":false,"error":{"code":"busy","message":"too many control clients; try again later"}})"
    "\n";

}  // namespace

ControlServer::ControlServer(ControlServerOptions options, Handler handler)
    : options_(std::move(options)), handler_(std::move(handler)) {}

ControlServer::~ControlServer() { close_all(); }

Status ControlServer::open() {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (options_.path.empty() || options_.path.size() >= sizeof address.sun_path) {
    return Status::failure("control socket path '" + options_.path + "' is empty or too long");
  }
  std::memcpy(address.sun_path, options_.path.c_str(), options_.path.size() + 1);
  const std::filesystem::path directory = std::filesystem::path(options_.path).parent_path();
  std::error_code ec;
  if (!directory.empty() && !std::filesystem::exists(directory, ec)) {
    if (!std::filesystem::create_directories(directory, ec)) {
      return Status::failure("cannot create " + directory.string() + ": " + ec.message());
    }
    ::chmod(directory.c_str(), options_.directory_mode);
    // The socket's group must be able to reach it: the directory gets the same group.
    if (options_.socket_group && ::chown(directory.c_str(), static_cast<uid_t>(-1), *options_.socket_group) != 0) {
      return Status::failure(errno_text("chown " + directory.string()));
    }
  }
  if (someone_listens(address)) return Status::failure("another cosmicd is listening on " + options_.path);
  ::unlink(options_.path.c_str());
  listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return Status::failure(errno_text("socket"));
  const mode_t previous = ::umask(0177);
  const int bound = ::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  ::umask(previous);
  if (bound != 0) return Status::failure(errno_text("bind " + options_.path));
  if (options_.socket_group && ::chown(options_.path.c_str(), static_cast<uid_t>(-1), *options_.socket_group) != 0) {
    return Status::failure(errno_text("chown " + options_.path));
  }
  if (::chmod(options_.path.c_str(), options_.socket_mode) != 0) return Status::failure(errno_text("chmod " + options_.path));
  if (::listen(listen_fd_, 64) != 0) return Status::failure(errno_text("listen"));
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd_ < 0) return Status::failure(errno_text("epoll_create1"));
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = listen_fd_;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, listen_fd_, &event);
  for (const auto& [fd, callback] : watches_) {
    epoll_event watch{};
    watch.events = EPOLLIN;
    watch.data.fd = fd;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &watch);
  }
  return Status::success();
}

void ControlServer::watch(int fd, std::function<void()> on_ready) {
  watches_[fd] = std::move(on_ready);
  if (epoll_fd_ < 0) return;
  epoll_event event{};
  event.events = EPOLLIN;
  event.data.fd = fd;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &event);
}

void ControlServer::run_for(std::chrono::milliseconds duration) {
  if (epoll_fd_ < 0) return;
  epoll_event events[32];
  const int ready = ::epoll_wait(epoll_fd_, events, 32, static_cast<int>(duration.count()));
  for (int i = 0; i < ready; ++i) {
    const int fd = events[i].data.fd;
    if (fd == listen_fd_) {
      accept_clients();
    } else if (const auto watch = watches_.find(fd); watch != watches_.end()) {
      watch->second();
    } else {
      on_client(fd, events[i].events);
    }
  }
  expire_idle();
}

void ControlServer::accept_clients() {
  while (true) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;
    if (clients_.size() >= options_.max_clients) {
      [[maybe_unused]] const auto written = ::write(fd, kBusy.data(), kBusy.size());
      ::close(fd);
      continue;
    }
    Client client;
    ucred credentials{};
    socklen_t length = sizeof credentials;
    if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &credentials, &length) == 0) {
      client.peer = PeerCredentials{credentials.pid, credentials.uid, credentials.gid};
    } else {
      client.peer = PeerCredentials{-1, static_cast<unsigned>(-1), static_cast<unsigned>(-1)};
    }
    client.last_activity = std::chrono::steady_clock::now();
    epoll_event event{};
    event.events = EPOLLIN | EPOLLRDHUP;
    event.data.fd = fd;
    ::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &event);
    clients_.emplace(fd, std::move(client));
  }
}

void ControlServer::on_client(int fd, std::uint32_t events) {
  const auto it = clients_.find(fd);
  if (it == clients_.end()) return;
  Client& client = it->second;
  client.last_activity = std::chrono::steady_clock::now();
  if (events & EPOLLIN) {
    char buffer[4096];
    while (true) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n > 0) {
        client.in.append(buffer, static_cast<std::size_t>(n));
        if (client.in.size() > options_.max_request_bytes + 1) break;
        continue;
      }
      if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) client.closing = true;
      if (n < 0 && errno == EINTR) continue;
      break;
    }
    answer_requests(client);
    const std::size_t newline = client.in.find('\n');
    if ((newline == std::string::npos ? client.in.size() : newline) > options_.max_request_bytes) {
      client.out += kTooLarge;
      client.in.clear();
      client.closing = true;
    }
  }
  if (events & (EPOLLHUP | EPOLLERR)) {
    drop(fd);
    return;
  }
  if (events & EPOLLRDHUP) client.closing = true;
  flush(fd, client);
}

void ControlServer::answer_requests(Client& client) {
  std::size_t newline;
  while (client.out.size() < options_.max_pending_output && (newline = client.in.find('\n')) != std::string::npos &&
         newline <= options_.max_request_bytes) {
    const std::string line = client.in.substr(0, newline);
    client.in.erase(0, newline + 1);
    if (!line.empty()) client.out += handler_(line, client.peer);
  }
}

void ControlServer::flush(int fd, Client& client) {
  while (true) {
    while (!client.out.empty()) {
      const ssize_t n = ::send(fd, client.out.data(), client.out.size(), MSG_NOSIGNAL);
      if (n > 0) {
        client.out.erase(0, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        update_interest(fd, client);  // the rest when the socket drains (EPOLLOUT)
        return;
      }
      drop(fd);
      return;
    }
    if (client.in.find('\n') != std::string::npos) {
      answer_requests(client);  // requests held back while the output was full
      if (!client.out.empty()) continue;
    }
    if (client.closing) {
      drop(fd);
      return;
    }
    update_interest(fd, client);
    return;
  }
}

void ControlServer::update_interest(int fd, const Client& client) {
  epoll_event event{};
  // A client with a full output buffer is not read until it reads its answers.
  const bool room = client.out.size() < options_.max_pending_output;
  event.events = EPOLLRDHUP | (room ? static_cast<std::uint32_t>(EPOLLIN) : 0u) |
                 (client.out.empty() ? 0u : static_cast<std::uint32_t>(EPOLLOUT));
  event.data.fd = fd;
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_MOD, fd, &event);
}

void ControlServer::drop(int fd) {
  ::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  ::close(fd);
  clients_.erase(fd);
}

void ControlServer::expire_idle() {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = clients_.begin(); it != clients_.end();) {
    const int fd = it->first;
    const bool idle = now - it->second.last_activity > options_.idle_timeout;
    ++it;
    if (idle) drop(fd);
  }
}

void ControlServer::close_all() {
  while (!clients_.empty()) drop(clients_.begin()->first);
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    ::unlink(options_.path.c_str());
    listen_fd_ = -1;
  }
  if (epoll_fd_ >= 0) {
    ::close(epoll_fd_);
    epoll_fd_ = -1;
  }
}

}  // namespace cosmic

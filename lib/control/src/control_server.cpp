#include "cosmic/thread_policy.hpp"
#include "cosmic/control_server.hpp"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

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

std::string error_line(const char* code, const std::string& message) {
  return nlohmann::json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}}.dump() + "\n";
}

// Best effort: the refused peer may already be gone, and a refusal must never block.
void refuse(int fd, const std::string& line) {
  [[maybe_unused]] const auto written = ::send(fd, line.data(), line.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  ::close(fd);
}

int open_spare_descriptor() { return ::open("/dev/null", O_RDONLY | O_CLOEXEC); }

void epoll_add(int epoll_fd, int fd, std::uint32_t events) {
  epoll_event event{};
  event.events = events;
  event.data.fd = fd;
  ::epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &event);
}

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
  struct stat existing {};
  if (::lstat(options_.path.c_str(), &existing) == 0 && !S_ISSOCK(existing.st_mode)) {
    return Status::failure("control socket path " + options_.path +
                           " exists and is not a socket; refusing to replace it (remove it or choose another path)");
  }
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
  ::unlink(options_.path.c_str());  // a stale socket (checked above: never another kind of file)
  listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return Status::failure(errno_text("socket"));
  const mode_t previous = ::umask(0177);
  const int bound = ::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  ::umask(previous);
  if (bound != 0) return Status::failure(errno_text("bind " + options_.path));
  struct stat created {};
  if (::lstat(options_.path.c_str(), &created) == 0) socket_inode_ = created.st_ino;
  if (options_.socket_group && ::chown(options_.path.c_str(), static_cast<uid_t>(-1), *options_.socket_group) != 0) {
    return Status::failure(errno_text("chown " + options_.path));
  }
  if (::chmod(options_.path.c_str(), options_.socket_mode) != 0)
    return Status::failure(errno_text("chmod " + options_.path));
  if (::listen(listen_fd_, 64) != 0) return Status::failure(errno_text("listen"));
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd_ < 0) return Status::failure(errno_text("epoll_create1"));
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) return Status::failure(errno_text("eventfd"));
  spare_fd_ = open_spare_descriptor();
  epoll_add(epoll_fd_, listen_fd_, EPOLLIN);
  epoll_add(epoll_fd_, wake_fd_, EPOLLIN);
  for (const auto& [fd, callback] : watches_) epoll_add(epoll_fd_, fd, EPOLLIN);
  return Status::success();
}

void ControlServer::watch(int fd, std::function<void()> on_ready) {
  watches_[fd] = std::move(on_ready);
  if (epoll_fd_ >= 0) epoll_add(epoll_fd_, fd, EPOLLIN);
}

void ControlServer::post(std::function<void()> task) {
  {
    LockGuard lock(posted_mutex_);
    posted_.push_back(std::move(task));
  }
  const std::uint64_t one = 1;
  if (wake_fd_ >= 0) [[maybe_unused]]
    const auto written = ::write(wake_fd_, &one, sizeof one);
}

Offload ControlServer::offload() {
  return [this](std::function<void()> work, std::function<void()> done) {
    LockGuard lock(jobs_mutex_);
    if (stopping_) return;
    jobs_.emplace_back(std::move(work), std::move(done));
    if (!worker_.joinable()) worker_ = std::thread([this] { work_loop(); });
    jobs_ready_.notify_one();
  };
}

void ControlServer::work_loop() {
  apply_thread_policy(ThreadPolicy{"ctl-worker", 0, 0, {}});  // a name only; runs as cosmicd's control thread
  while (true) {
    std::pair<std::function<void()>, std::function<void()>> job;
    {
      UniqueLock lock(jobs_mutex_);
      while (!stopping_ && jobs_.empty()) lock.wait(jobs_ready_);
      if (stopping_) return;
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    job.first();
    post(std::move(job.second));
  }
}

void ControlServer::stop_worker() {
  std::thread worker;  // joined outside the lock, which the worker takes to see stopping_
  {
    LockGuard lock(jobs_mutex_);
    stopping_ = true;
    jobs_.clear();
    worker = std::move(worker_);
  }
  jobs_ready_.notify_all();
  if (worker.joinable()) worker.join();
}

void ControlServer::run_posted() {
  std::uint64_t count = 0;
  [[maybe_unused]] const auto drained = ::read(wake_fd_, &count, sizeof count);
  std::vector<std::function<void()>> tasks;
  {
    LockGuard lock(posted_mutex_);
    tasks.swap(posted_);
  }
  for (auto& task : tasks) task();
}

void ControlServer::run_for(std::chrono::milliseconds duration) {
  if (epoll_fd_ < 0) return;
  if (spare_fd_ < 0) spare_fd_ = open_spare_descriptor();
  epoll_event events[32];
  const int ready = ::epoll_wait(epoll_fd_, events, 32, static_cast<int>(duration.count()));
  for (int i = 0; i < ready; ++i) {
    const int fd = events[i].data.fd;
    if (fd == listen_fd_) {
      accept_clients();
    } else if (fd == wake_fd_) {
      run_posted();
    } else if (const auto watch = watches_.find(fd); watch != watches_.end()) {
      watch->second();
    } else {
      on_client(fd, events[i].events);
    }
  }
  expire();
}

void ControlServer::accept_clients() {
  while (true) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd >= 0) {
      add_client(fd);
      continue;
    }
    if (errno == EINTR || errno == ECONNABORTED) continue;
    // accept4 takes a descriptor before it looks for a connection, so at the limit it answers
    // EMFILE even with an empty backlog: go on only while the spare actually took one off it.
    if ((errno == EMFILE || errno == ENFILE) && spare_fd_ >= 0 && refuse_at_fd_limit()) continue;
    // EAGAIN, or out of descriptors with no spare: a waiting connection stays in the backlog
    // and the level-triggered listener would wake us at once, so the next try waits for the
    // next run_for() (the spare is reopened there).
    return;
  }
}

// Out of file descriptors: the pending connection would keep the listener readable and the loop
// spinning. Give up the spare descriptor, take the connection, tell the peer why, close it.
// False when there was no connection to take (the backlog is empty).
bool ControlServer::refuse_at_fd_limit() {
  ::close(spare_fd_);
  spare_fd_ = -1;
  const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (fd >= 0) {
    ++refused_at_fd_limit_;
    refuse(fd, error_line("busy", "cosmicd is out of file descriptors; try again later"));
  }
  spare_fd_ = open_spare_descriptor();
  return fd >= 0;
}

Result<void> ControlServer::admit(const Client& client) const {
  if (clients_.size() >= options_.max_clients) return Error{"too many control clients; try again later"};
  if (client.privileged) return {};
  const std::size_t reserve = std::min(options_.privileged_reserve, options_.max_clients);
  if (clients_.size() >= options_.max_clients - reserve) {
    return Error{"the remaining control connections are reserved for administrators; try again later"};
  }
  std::size_t same_uid = 0;
  for (const auto& [fd, other] : clients_) same_uid += (!other.privileged && other.peer.uid == client.peer.uid) ? 1 : 0;
  if (same_uid >= options_.max_clients_per_uid) {
    return Error{"uid " + std::to_string(client.peer.uid) + " already holds " + std::to_string(same_uid) +
                 " control connections (the limit per user); close one first"};
  }
  return {};
}

void ControlServer::add_client(int fd) {
  Client client;
  ucred credentials{};
  socklen_t length = sizeof credentials;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &credentials, &length) == 0) {
    client.peer = PeerCredentials{credentials.pid, credentials.uid, credentials.gid};
  } else {
    client.peer = PeerCredentials{-1, static_cast<unsigned>(-1), static_cast<unsigned>(-1)};
  }
  client.privileged = options_.privileged && options_.privileged(client.peer);
  if (const Result<void> admitted = admit(client); !admitted) {
    refuse(fd, error_line("busy", admitted.error().text));
    return;
  }
  client.id = next_client_id_++;
  client.last_activity = Clock::now();
  epoll_add(epoll_fd_, fd, EPOLLIN | EPOLLRDHUP);
  clients_.emplace(fd, std::move(client));
}

void ControlServer::on_client(int fd, std::uint32_t events) {
  const auto it = clients_.find(fd);
  if (it == clients_.end()) return;
  Client& client = it->second;
  if (events & EPOLLIN) read_input(client, fd);
  if (events & (EPOLLHUP | EPOLLERR)) {
    drop(fd);
    return;
  }
  if (events & EPOLLRDHUP) client.closing = true;
  flush(fd, client);
}

void ControlServer::read_input(Client& client, int fd) {
  char buffer[4096];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n > 0) {
      if (client.in.empty()) client.request_started = Clock::now();
      client.in.append(buffer, static_cast<std::size_t>(n));
      if (client.in.size() > options_.max_request_bytes + 1) break;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) client.closing = true;
    break;
  }
  answer_requests(fd, client);
  const std::size_t newline = client.in.find('\n');
  if ((newline == std::string::npos ? client.in.size() : newline) > options_.max_request_bytes) {
    client.out += error_line("too_large", "request larger than the limit of " +
                                              std::to_string(options_.max_request_bytes) + " bytes; connection closed");
    client.in.clear();
    client.closing = true;
  }
}

void ControlServer::answer_requests(int fd, Client& client) {
  std::size_t newline;
  while (!client.awaiting_answer && client.out.size() < options_.max_pending_output &&
         (newline = client.in.find('\n')) != std::string::npos && newline <= options_.max_request_bytes) {
    const std::string line = client.in.substr(0, newline);
    client.in.erase(0, newline + 1);
    const auto now = Clock::now();
    client.request_started = now;  // of what follows in `in`
    if (line.empty()) continue;
    client.last_activity = now;
    client.awaiting_answer = true;
    const std::uint64_t id = client.id;
    client.in_handler = true;
    auto answer = handler_(line, client.peer, [this, fd, id](const std::string& text) { deliver(fd, id, text); });
    client.in_handler = false;
    if (answer) {
      client.awaiting_answer = false;
      client.out += *answer;
    }
  }
}

// A deferred answer: only for the connection that asked (a reused descriptor has another id).
void ControlServer::deliver(int fd, std::uint64_t id, const std::string& line) {
  const auto it = clients_.find(fd);
  if (it == clients_.end() || it->second.id != id || !it->second.awaiting_answer) return;
  Client& client = it->second;
  client.out += line;
  client.awaiting_answer = false;
  client.last_activity = Clock::now();
  if (!client.in_handler) flush(fd, client);
}

void ControlServer::flush(int fd, Client& client) {
  while (true) {
    while (!client.out.empty()) {
      const ssize_t n = ::send(fd, client.out.data(), client.out.size(), MSG_NOSIGNAL);
      if (n > 0) {
        client.out.erase(0, static_cast<std::size_t>(n));
        client.last_activity = Clock::now();
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        update_interest(fd, client);  // the rest when the socket drains (EPOLLOUT)
        return;
      }
      drop(fd);
      return;
    }
    if (!client.awaiting_answer && client.in.find('\n') != std::string::npos) {
      answer_requests(fd, client);  // requests held back while the output was full
      if (!client.out.empty()) continue;
    }
    if (client.closing && !client.awaiting_answer) {
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

// Incomplete requests get a deadline from their first byte (trickling bytes does not extend
// it); connections with nothing in progress get the idle timeout. A client waiting for a
// deferred answer waits for us, not we for it.
void ControlServer::expire() {
  const auto now = Clock::now();
  std::vector<int> late;
  std::vector<int> idle;
  for (const auto& [fd, client] : clients_) {
    if (client.awaiting_answer) continue;
    const bool incomplete = !client.in.empty() && client.in.find('\n') == std::string::npos &&
                            client.out.size() < options_.max_pending_output;
    if (incomplete && now - client.request_started > options_.request_timeout) {
      late.push_back(fd);
    } else if (!incomplete && now - client.last_activity > options_.idle_timeout) {
      idle.push_back(fd);
    }
  }
  for (const int fd : idle) drop(fd);
  const auto seconds = std::chrono::duration<double>(options_.request_timeout).count();
  for (const int fd : late) {
    Client& client = clients_.at(fd);
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", seconds);
    client.out += error_line("timeout", std::string("request not complete within ") + limit + " s; connection closed");
    client.in.clear();
    client.closing = true;
    flush(fd, client);
  }
}

void ControlServer::close_all() {
  stop_worker();
  while (!clients_.empty()) drop(clients_.begin()->first);
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    // Only our own socket: the path may have been replaced since.
    struct stat current {};
    if (::lstat(options_.path.c_str(), &current) == 0 && S_ISSOCK(current.st_mode) && current.st_ino == socket_inode_) {
      ::unlink(options_.path.c_str());
    }
  }
  for (int* fd : {&epoll_fd_, &wake_fd_, &spare_fd_}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
}

}  // namespace cosmic

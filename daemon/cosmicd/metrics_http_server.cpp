#include "metrics_http_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>

#include "metrics_http_head.hpp"

namespace cosmicd {
namespace {

using Clock = std::chrono::steady_clock;

std::string refusal(std::string_view status, std::string_view body) {
  return "HTTP/1.1 " + std::string(status) +
         "\r\nContent-Type: text/plain\r\nContent-Length: " + std::to_string(body.size()) +
         "\r\nConnection: close\r\n\r\n" + std::string(body);
}
const std::string kRequestTimeout = refusal("408 Request Timeout", "the request head did not arrive in time\n");
const std::string kHeadTooLarge = refusal("431 Request Header Fields Too Large", "the request head is too large\n");
constexpr std::chrono::minutes kEvictionReportEvery{1};

// Waits until `fd` is ready for `events` (or has hung up) or `deadline` passes.
bool wait_for(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, events, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 60'000)));
    if (ready > 0) return true;
    if (ready < 0 && errno != EINTR) return false;
  }
}

// One send that never blocks: for the short refusals before closing.
void send_refusal(int fd, std::string_view text) {
  [[maybe_unused]] const ssize_t sent = ::send(fd, text.data(), text.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

void address_of(const sockaddr_storage& address, std::string& ip, int& port) {
  char text[INET6_ADDRSTRLEN] = {};
  if (address.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(address);
    ::inet_ntop(AF_INET, &v4.sin_addr, text, sizeof text);
    port = ntohs(v4.sin_port);
  } else if (address.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(address);
    ::inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof text);
    port = ntohs(v6.sin6_port);
  }
  ip = text;
}

// What cpp-httplib reads a request from and writes its answer to. It reads `buffered` first (the
// head as RequestHead forwards it, and whatever arrived after it), then the socket until
// `read_deadline`; it writes the answer by `write_deadline`. Nothing here blocks past a deadline.
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(int fd, std::string buffered, Clock::time_point read_deadline, Clock::time_point write_deadline)
      : fd_(fd), buffered_(std::move(buffered)), read_deadline_(read_deadline), write_deadline_(write_deadline) {}

  bool is_readable() const override {
    return offset_ < buffered_.size() || (fd_ >= 0 && wait_for(fd_, POLLIN, read_deadline_));
  }
  bool is_writable() const override { return fd_ >= 0 && wait_for(fd_, POLLOUT, write_deadline_); }

  ssize_t read(char* ptr, size_t size) override {
    if (offset_ < buffered_.size()) {
      const std::size_t n = std::min(size, buffered_.size() - offset_);
      std::copy_n(buffered_.data() + offset_, n, ptr);
      offset_ += n;
      return static_cast<ssize_t>(n);
    }
    if (fd_ < 0) return 0;
    for (;;) {
      if (!wait_for(fd_, POLLIN, read_deadline_)) return -1;
      const ssize_t n = ::recv(fd_, ptr, size, MSG_DONTWAIT);
      if (n >= 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) return n;
    }
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (fd_ < 0) {
      written_.append(ptr, size);
      return static_cast<ssize_t>(size);
    }
    std::size_t done = 0;
    while (done < size) {
      if (!wait_for(fd_, POLLOUT, write_deadline_)) break;
      const ssize_t n = ::send(fd_, ptr + done, size - done, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    if (done < size) failed_ = true;
    return done == 0 && size > 0 ? -1 : static_cast<ssize_t>(done);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { endpoint(::getpeername, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { endpoint(::getsockname, ip, port); }
  socket_t socket() const override { return fd_; }

  bool failed() const { return failed_; }
  // What was received but not read: the start of the next request.
  std::string unread() && { return buffered_.substr(std::min(offset_, buffered_.size())); }
  const std::string& written() const { return written_; }

 private:
  template <typename Query>
  void endpoint(Query query, std::string& ip, int& port) const {
    ip.clear();
    port = 0;
    sockaddr_storage address{};
    socklen_t length = sizeof address;
    if (fd_ >= 0 && query(fd_, reinterpret_cast<sockaddr*>(&address), &length) == 0) address_of(address, ip, port);
  }

  int fd_;  // -1: no socket, what is written is kept (answer())
  std::string buffered_;
  std::size_t offset_ = 0;
  Clock::time_point read_deadline_;
  Clock::time_point write_deadline_;
  std::string written_;
  bool failed_ = false;
};

}  // namespace

MetricsHttpServer::MetricsHttpServer(HttpLimits limits, std::function<void()> on_thread_start, cosmic::Logger* log)
    : limits_(limits), log_(log), registry_(limits.max_connections, [this](std::uint64_t n) { report_evictions(n); }) {
  new_task_queue = [this, on_thread_start = std::move(on_thread_start)] {
    return new ConnectionPool(registry_, on_thread_start);
  };
  // What cpp-httplib still applies itself: the Keep-Alive header it writes, request bodies.
  set_keep_alive_timeout(std::max<time_t>(1, std::chrono::ceil<std::chrono::seconds>(limits.keep_alive).count()));
  set_keep_alive_max_count(limits.max_requests_per_connection);
  set_payload_max_length(limits.max_head_bytes);
}

bool MetricsHttpServer::bind(const std::string& host, int port, int backlog) {
  if (!bind_to_port(host, port)) return false;
  ::listen(svr_sock_, backlog);  // Linux: listen() again sets the backlog of a listening socket
  return true;
}

void MetricsHttpServer::serve_metrics(DocumentSource document) {
  Get("/metrics", [document = std::move(document)](const httplib::Request& request, httplib::Response& response) {
    const ExpositionFormat format = format_for_accept(request.get_header_value("Accept"));
    std::optional<std::string> text = document(format);
    if (!text) {
      response.status = 503;
      response.set_content("cosmicd did not answer with a snapshot in time\n", "text/plain");
      return;
    }
    response.set_content(*text, content_type(format));
  });
  Get("/", [](const httplib::Request&, httplib::Response& response) {
    response.set_content("cosmicd: metrics at /metrics\n", "text/plain");
  });
}

bool MetricsHttpServer::serve_request(httplib::Stream& stream, bool last) {
  bool closed = false;
  const bool ok = process_request(stream, last, closed, [](httplib::Request& request) { request.ranges.clear(); });
  return ok && !closed && !last;
}

std::string MetricsHttpServer::answer(std::string_view bytes) {
  RequestHead head(limits_.max_head_bytes);
  const std::size_t used = head.feed(bytes);
  if (head.state() == RequestHead::State::too_large) return kHeadTooLarge;
  if (head.state() != RequestHead::State::complete) return {};
  ConnectionStream stream(-1, head.forwarded() + std::string(bytes.substr(used)), Clock::now(), Clock::now());
  serve_request(stream, true);
  return stream.written();
}

bool MetricsHttpServer::process_and_close_socket(socket_t sock) {
  if (registry_.add(sock)) {
    try {
      serve_connection(sock);
    } catch (...) {  // cpp-httplib answers a handler's exception itself; anything else ends the connection
    }
    registry_.remove(sock);
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return true;
}

void MetricsHttpServer::serve_connection(int fd) {
  std::string carry;  // received after the last head: the start of the next request
  auto idle_limit = limits_.first_request_wait;
  for (std::size_t served = 0; served < limits_.max_requests_per_connection; ++served) {
    registry_.set(fd, ConnectionState::idle);
    if (carry.empty() && !wait_for(fd, POLLIN, Clock::now() + idle_limit)) return;
    registry_.set(fd, ConnectionState::reading);
    const auto head_deadline = Clock::now() + limits_.head_deadline;
    RequestHead head(limits_.max_head_bytes);
    carry.erase(0, head.feed(carry));
    char buffer[4096];
    while (head.state() == RequestHead::State::incomplete) {
      if (!wait_for(fd, POLLIN, head_deadline)) {
        send_refusal(fd, kRequestTimeout);
        return;
      }
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) continue;
      if (n <= 0) return;
      const std::string_view received(buffer, static_cast<std::size_t>(n));
      carry.append(received.substr(head.feed(received)));
    }
    if (head.state() == RequestHead::State::too_large) {
      send_refusal(fd, kHeadTooLarge);
      return;
    }
    registry_.set(fd, ConnectionState::serving);
    ConnectionStream stream(fd, head.forwarded() + carry, head_deadline, Clock::now() + limits_.write_deadline);
    const bool more = serve_request(stream, served + 1 == limits_.max_requests_per_connection);
    if (!more || stream.failed()) return;
    carry = std::move(stream).unread();
    idle_limit = limits_.keep_alive;
  }
}

void MetricsHttpServer::report_evictions(std::uint64_t evictions) {
  if (!log_) return;
  std::uint64_t since_last = 0;
  {
    std::lock_guard lock(report_mutex_);
    const auto now = Clock::now();
    if (reported_ != 0 && now - last_report_ < kEvictionReportEvery) return;
    since_last = evictions - reported_;
    reported_ = evictions;
    last_report_ = now;
  }
  log_->log(cosmic::LogLevel::warning,
            "metrics endpoint: " + std::to_string(since_last) + " connection(s) closed at the cap of " +
                std::to_string(limits_.max_connections) +
                " connections (the longest idle first); next report in a minute at the earliest");
}

}  // namespace cosmicd

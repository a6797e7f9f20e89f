// The HTTP server of the metrics endpoint: cpp-httplib's parsing and routing, with the connection
// handling that keeps the endpoint answering under hostile clients (issue 22, item 3) done here:
//   - every connection runs at once on its own thread, at most `max_connections` of them; a new
//     one at the cap closes the connection idle the longest (ConnectionRegistry), so descriptors
//     and threads stay bounded and idle connections cannot lock scrapers out;
//   - a request head must arrive whole within `head_deadline` of its first byte and hold at most
//     `max_head_bytes` (else 408 or 431, and the connection is closed); between requests a
//     connection may idle `keep_alive`; a response must be written within `write_deadline`;
//   - Range and If-Range are dropped from the head before cpp-httplib sees it (RequestHead), and
//     the ranges of every request are cleared: the answer is always the whole document.
// cpp-httplib (0.11.4) makes this possible through Server::process_and_close_socket (virtual),
// process_request (protected, reads from any httplib::Stream) and new_task_queue.
//
// Threads: construct, serve_metrics() and listen from one thread; close_connections() and stop()
// from any. Connections are served on ConnectionPool threads, all set up by `on_thread_start`.
#pragma once

#include <httplib.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/log.hpp"
#include "metrics_exposition.hpp"
#include "metrics_http_connections.hpp"

namespace cosmicd {

struct HttpLimits {
  std::size_t max_connections = 8;
  std::size_t max_head_bytes = 4096;
  std::chrono::milliseconds first_request_wait{3000};  // a new connection, until its first byte
  std::chrono::milliseconds keep_alive{1000};          // between requests on one connection
  std::chrono::milliseconds head_deadline{3000};       // from a head's first byte to its last
  std::chrono::milliseconds write_deadline{10000};     // a whole response
  std::size_t max_requests_per_connection = 100;
};

// The /metrics document in `format`, or nothing (the endpoint answers 503).
using DocumentSource = std::function<std::optional<std::string>(ExpositionFormat format)>;

class MetricsHttpServer : public httplib::Server {
 public:
  // `log` (may be null) hears of evictions, at most once a minute.
  MetricsHttpServer(HttpLimits limits, std::function<void()> on_thread_start, cosmic::Logger* log);

  // bind_to_port, with a listen backlog of `backlog` instead of cpp-httplib's 5, so a scraper's
  // connection is not dropped by the kernel while a flood of others waits to be accepted.
  bool bind(const std::string& host, int port, int backlog = 128);

  // GET /metrics from `document`, GET / says where the metrics are; everything else 404.
  void serve_metrics(DocumentSource document);

  // Closes every connection now, and every one accepted from now on: call before stop() so
  // stopping never waits for a deadline.
  void close_connections() { registry_.stop(); }

  // What the server writes for `bytes` arriving on a fresh connection, without a socket: the head
  // limit, then cpp-httplib's parsing and routing of one request (tests, fuzz target). Empty when
  // the head is incomplete (a connection would wait for more, then answer 408).
  std::string answer(std::string_view bytes);

  const ConnectionRegistry& connections() const { return registry_; }

 private:
  bool process_and_close_socket(socket_t sock) override;
  void serve_connection(int fd);
  // One request whose head is complete, through cpp-httplib; false when the connection must close.
  bool serve_request(httplib::Stream& stream, bool last);
  void report_evictions(std::uint64_t evictions);

  const HttpLimits limits_;
  cosmic::Logger* const log_;
  ConnectionRegistry registry_;
  std::mutex report_mutex_;
  std::chrono::steady_clock::time_point last_report_{};
  std::uint64_t reported_ = 0;
};

}  // namespace cosmicd

// Unix stream socket server of the control protocol: many clients at once (epoll), one JSON
// request per line, a cap on request size, an idle timeout and a client limit. Single-threaded:
// the owner calls run_for() in its control loop; the handler runs on that thread.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <sys/types.h>

#include "cosmic/control_protocol.hpp"

namespace cosmic {

struct ControlServerOptions {
  std::string path;
  std::size_t max_request_bytes = 64 * 1024;
  std::size_t max_clients = 32;
  std::size_t max_pending_output = 1u << 20;  // a client that does not read its answers is paused
  std::chrono::milliseconds idle_timeout{30'000};
  mode_t socket_mode = 0660;
  mode_t directory_mode = 0750;      // for a directory the server has to create
  std::optional<gid_t> socket_group;  // chown the socket to this group
};

class ControlServer {
 public:
  using Handler = std::function<std::string(std::string_view line, const PeerCredentials& peer)>;

  ControlServer(ControlServerOptions options, Handler handler);
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  // Creates the socket (and its directory). Refuses when another server is listening there.
  Status open();
  // Adds another descriptor to the loop (e.g. a signalfd); `on_ready` runs when it is readable.
  void watch(int fd, std::function<void()> on_ready);
  // Serves for up to `duration`, returning earlier after handling some events.
  void run_for(std::chrono::milliseconds duration);
  void close_all();
  std::size_t client_count() const { return clients_.size(); }

 private:
  struct Client {
    std::string in;
    std::string out;
    PeerCredentials peer;
    std::chrono::steady_clock::time_point last_activity;
    bool closing = false;  // close once `out` is written
  };
  void accept_clients();
  void on_client(int fd, std::uint32_t events);
  void flush(int fd, Client& client);
  // Answers the complete request lines buffered for `client` while its output has room.
  void answer_requests(Client& client);
  void drop(int fd);
  void expire_idle();
  void update_interest(int fd, const Client& client);

  ControlServerOptions options_;
  Handler handler_;
  int epoll_fd_ = -1;
  int listen_fd_ = -1;
  std::map<int, Client> clients_;
  std::map<int, std::function<void()>> watches_;
};

}  // namespace cosmic

// Unix stream socket server of the control protocol: many clients at once (epoll), one JSON
// request per line, a cap on request size, a deadline for incomplete requests, an idle timeout,
// a client limit with a reserve for privileged peers and a per-uid share.
//
// Threads: single-threaded. The owner calls run_for() in its control loop; the handler, every
// `watch` callback and every posted task run on that thread. Only post() may be called from any
// thread: it queues a task and wakes the loop (eventfd), which is how work finished elsewhere
// (e.g. an admission on a worker thread) answers a deferred request. The server also owns one
// worker thread for such work (offload()); close_all() waits for the job it is running.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <sys/types.h>
#include <thread>
#include <utility>
#include <vector>

#include "cosmic/control_protocol.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/result.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

struct ControlServerOptions {
  std::string path;
  std::size_t max_request_bytes = std::size_t{64} * 1024;
  std::size_t max_clients = 32;
  // Slots only privileged peers may take, so unprivileged readers cannot lock admins (and
  // `systemctl reload` through cosmicctl) out.
  std::size_t privileged_reserve = 4;
  // Connections one unprivileged uid may hold at once.
  std::size_t max_clients_per_uid = 8;
  std::size_t max_pending_output = 1u << 20;  // a client that does not read its answers is paused
  // A request line must be complete this long after its first byte arrived; trickling bytes
  // does not extend it.
  std::chrono::milliseconds request_timeout{5'000};
  // A connection with no request in progress and nothing to send is closed after this.
  std::chrono::milliseconds idle_timeout{30'000};
  mode_t socket_mode = 0660;
  mode_t directory_mode = 0750;       // for a directory the server has to create
  std::optional<gid_t> socket_group;  // chown the socket to this group
  // Peers that may use the reserved slots and are not limited per uid (e.g. root and the admin
  // group). Called on the control thread at accept().
  std::function<bool(const PeerCredentials&)> privileged = [](const PeerCredentials& peer) { return peer.uid == 0; };
};

class ControlServer {
 public:
  // Answers a request later, exactly once, on the control thread. Answering a client that
  // has gone away is a no-op.
  using Responder = std::function<void(std::string line)>;
  // Returns the answer line now, or nullopt after keeping `later` to answer through it. While
  // an answer is outstanding, that client's further requests wait (answers keep their order).
  using Handler =
      std::function<std::optional<std::string>(std::string_view line, const PeerCredentials& peer, Responder later)>;

  ControlServer(ControlServerOptions options, Handler handler);
  ~ControlServer();
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  // Creates the socket (and its directory). Refuses when another server is listening there and
  // when the path exists as anything but a socket (it is never deleted then).
  Status open();
  // Adds another descriptor to the loop (e.g. a signalfd); `on_ready` runs when it is readable.
  void watch(int fd, std::function<void()> on_ready);
  // Any thread: runs `task` on the control thread during run_for().
  void post(std::function<void()> task) COSMIC_EXCLUDES(posted_mutex_);
  // Jobs for the server's worker thread, one at a time in order: `work` there, then `done`
  // posted to the control thread. Jobs not started by close_all() are dropped.
  Offload offload();
  // Serves for up to `duration`, returning earlier after handling some events.
  void run_for(std::chrono::milliseconds duration);
  void close_all();
  std::size_t client_count() const { return clients_.size(); }
  // Connections refused at accept() because the process ran out of file descriptors.
  std::uint64_t refused_at_fd_limit() const { return refused_at_fd_limit_; }

 private:
  using Clock = std::chrono::steady_clock;
  struct Client {
    std::uint64_t id = 0;  // unique for the server's life (descriptors are reused)
    std::string in;
    std::string out;
    PeerCredentials peer;
    bool privileged = false;
    Clock::time_point last_activity;
    Clock::time_point request_started;  // first byte of the incomplete request in `in`
    bool awaiting_answer = false;       // a deferred answer is outstanding
    bool in_handler = false;            // a responder called from inside the handler only queues
    bool closing = false;               // close once `out` is written
  };
  Result<void> admit(const Client& client) const;
  void accept_clients();
  bool refuse_at_fd_limit();
  void add_client(int fd);
  void on_client(int fd, std::uint32_t events);
  void read_input(Client& client, int fd);
  void flush(int fd, Client& client);
  // Answers the complete request lines buffered for `client` while its output has room.
  void answer_requests(int fd, Client& client);
  void deliver(int fd, std::uint64_t id, const std::string& line);
  void drop(int fd);
  void expire();
  void run_posted() COSMIC_EXCLUDES(posted_mutex_);
  void update_interest(int fd, const Client& client);
  void work_loop() COSMIC_EXCLUDES(jobs_mutex_);
  void stop_worker() COSMIC_EXCLUDES(jobs_mutex_);

  ControlServerOptions options_;
  Handler handler_;
  int epoll_fd_ = -1;
  int listen_fd_ = -1;
  int wake_fd_ = -1;   // eventfd: post() was called
  int spare_fd_ = -1;  // given up at EMFILE to accept and refuse one connection
  ino_t socket_inode_ = 0;
  std::uint64_t next_client_id_ = 1;
  std::uint64_t refused_at_fd_limit_ = 0;
  std::map<int, Client> clients_;
  std::map<int, std::function<void()>> watches_;
  Mutex posted_mutex_;
  std::vector<std::function<void()>> posted_ COSMIC_GUARDED_BY(posted_mutex_);
  Mutex jobs_mutex_;
  std::condition_variable jobs_ready_;
  std::deque<std::pair<std::function<void()>, std::function<void()>>> jobs_ COSMIC_GUARDED_BY(jobs_mutex_);
  bool stopping_ COSMIC_GUARDED_BY(jobs_mutex_) = false;
  std::thread worker_ COSMIC_GUARDED_BY(jobs_mutex_);  // started by the first job
};

}  // namespace cosmic

#include "test_support.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <iostream>
#include <stdexcept>

extern char** environ;

namespace cosmic::test {

bool eventually(const std::function<bool()>& condition, std::chrono::milliseconds within) {
  const auto deadline = deadline_in(within);
  while (!condition()) {
    if (Clock::now() >= deadline) {
      return condition();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// ---- Child ------------------------------------------------------------------------------------

Child::Child(std::vector<std::string> argv) : argv_(std::move(argv)) {
  signal(SIGPIPE, SIG_IGN);  // a child that already exited must not kill the test
  int out[2];
  int err[2];
  int in[2];
  if (pipe2(out, O_CLOEXEC) != 0 || pipe2(err, O_CLOEXEC) != 0 || pipe2(in, O_CLOEXEC) != 0) {
    throw std::runtime_error("pipe failed");
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in[0], 0);
  posix_spawn_file_actions_adddup2(&actions, out[1], 1);
  posix_spawn_file_actions_adddup2(&actions, err[1], 2);
  std::vector<char*> args;
  for (auto& a : argv_) args.push_back(a.data());
  args.push_back(nullptr);
  const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  close(err[1]);
  close(in[0]);
  stdin_fd_ = in[1];
  if (rc != 0) {
    close(out[0]);
    close(err[0]);
    throw std::runtime_error("posix_spawn " + argv_[0] + " failed: " + std::to_string(rc));
  }
  out_thread_ = std::thread([this, fd = out[0]] { pump(fd, out_); });
  err_thread_ = std::thread([this, fd = err[0]] { pump(fd, err_); });
}

Child::~Child() {
  if (!status_) {
    // SIGTERM lets the peer delete its DDS entities (and shared memory); SIGKILL if it hangs.
    kill(pid_, SIGTERM);
    if (!wait_exit(std::chrono::milliseconds(5000))) {
      kill(pid_, SIGKILL);
      int st = 0;
      waitpid(pid_, &st, 0);
    }
  }
  if (stdin_fd_ >= 0) close(stdin_fd_);
  out_thread_.join();
  err_thread_.join();
}

void Child::pump(int fd, std::vector<std::string>& lines) {
  std::string partial;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    partial.append(buf, static_cast<std::size_t>(n));
    std::size_t pos;
    bool added = false;
    while ((pos = partial.find('\n')) != std::string::npos) {
      std::lock_guard lock(mutex_);
      lines.push_back(partial.substr(0, pos));
      partial.erase(0, pos + 1);
      added = true;
    }
    if (added) cv_.notify_all();
  }
  if (!partial.empty()) {
    std::lock_guard lock(mutex_);
    lines.push_back(partial);
  }
  cv_.notify_all();
  close(fd);
}

bool Child::wait_lines(const std::vector<std::string>& lines, const std::function<bool(const std::string&)>& match,
                       std::chrono::milliseconds within) {
  std::unique_lock lock(mutex_);
  return cv_.wait_until(lock, deadline_in(within), [&] { return std::any_of(lines.begin(), lines.end(), match); });
}

bool Child::wait_out(const std::function<bool(const std::string&)>& match, std::chrono::milliseconds within) {
  return wait_lines(out_, match, within);
}

bool Child::wait_err(const std::function<bool(const std::string&)>& match, std::chrono::milliseconds within) {
  return wait_lines(err_, match, within);
}

std::optional<int> Child::wait_exit(std::chrono::milliseconds within) {
  if (status_) return status_;
  const auto deadline = deadline_in(within);
  for (;;) {
    int st = 0;
    const pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      return status_;
    }
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void Child::send_line(const std::string& line) {
  const std::string data = line + "\n";
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = write(stdin_fd_, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

std::vector<std::string> Child::out_lines() const {
  std::lock_guard lock(mutex_);
  return out_;
}

std::vector<std::string> Child::err_lines() const {
  std::lock_guard lock(mutex_);
  return err_;
}

std::string Child::describe() const {
  std::string text = "command:";
  for (const auto& a : argv_) text += " " + a;
  text += "\nstderr:\n";
  for (const auto& l : err_lines()) text += "  " + l + "\n";
  return text;
}

// ---- RecordingSink ----------------------------------------------------------------------------

void RecordingSink::on_event(const InboundEvent& event) {
  {
    std::lock_guard lock(mutex_);
    events_.push_back(Event{event.channel, event.header,
                            std::vector<std::uint8_t>(event.payload.begin(), event.payload.end()), event.received_at,
                            event.receiver_class});
  }
  cv_.notify_all();
}

void RecordingSink::on_problem(ChannelId, InboundProblem problem) {
  {
    std::lock_guard lock(mutex_);
    ++problems_[problem];
  }
  cv_.notify_all();
}

std::vector<RecordingSink::Event> RecordingSink::events() const {
  std::lock_guard lock(mutex_);
  return events_;
}

std::vector<RecordingSink::Event> RecordingSink::events_on(ChannelId channel) const {
  std::lock_guard lock(mutex_);
  std::vector<Event> out;
  for (const auto& e : events_) {
    if (e.channel == channel) out.push_back(e);
  }
  return out;
}

std::size_t RecordingSink::count_on(ChannelId channel) const { return events_on(channel).size(); }

std::size_t RecordingSink::problems(InboundProblem problem) const {
  std::lock_guard lock(mutex_);
  auto it = problems_.find(problem);
  return it == problems_.end() ? 0 : it->second;
}

bool RecordingSink::wait(const std::function<bool(const std::vector<Event>&, const Problems&)>& condition,
                         std::chrono::milliseconds within) {
  std::unique_lock lock(mutex_);
  return cv_.wait_until(lock, deadline_in(within), [&] { return condition(events_, problems_); });
}

bool RecordingSink::wait_count(ChannelId channel, std::size_t n, std::chrono::milliseconds within) {
  return wait(
      [&](const std::vector<Event>& events, const Problems&) {
        return static_cast<std::size_t>(std::count_if(events.begin(), events.end(),
                                                      [&](const Event& e) { return e.channel == channel; })) >= n;
      },
      within);
}

bool RecordingSink::wait_problems(InboundProblem problem, std::size_t n, std::chrono::milliseconds within) {
  return wait(
      [&](const std::vector<Event>&, const Problems& problems) {
        auto it = problems.find(problem);
        return it != problems.end() && it->second >= n;
      },
      within);
}

void StderrLogger::log(LogLevel level, std::string_view message) {
  static const char* names[] = {"debug", "info", "notice", "warning", "error"};
  std::lock_guard lock(mutex_);
  std::cerr << "[" << names[static_cast<int>(level)] << "] " << message << std::endl;
}

}  // namespace cosmic::test

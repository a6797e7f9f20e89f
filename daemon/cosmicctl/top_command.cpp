// cosmicctl top: a live view of a running cosmicd, redrawn every --interval seconds with plain
// ANSI escape sequences (works over ssh and in tmux, no curses). `q` or Ctrl-C quits.
#include <poll.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <csignal>
#include <ctime>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "control_client.hpp"
#include "top_view.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void on_stop_signal(int) { g_stop = 1; }

struct TopOptions {
  double interval = 1.0;
  int iterations = 0;  // 0: until q
};

// Raw keyboard input and the alternate screen while top runs; both undone on every exit path.
class Terminal {
 public:
  Terminal() : keys_(isatty(STDIN_FILENO)), screen_(isatty(STDOUT_FILENO)) {
    if (keys_ && tcgetattr(STDIN_FILENO, &saved_) == 0) {
      termios raw = saved_;
      raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);  // ISIG stays: Ctrl-C still stops us
      raw.c_cc[VMIN] = 0;
      raw.c_cc[VTIME] = 0;
      tcsetattr(STDIN_FILENO, TCSANOW, &raw);
    } else {
      keys_ = false;
    }
    if (screen_) std::cout << "\x1b[?1049h\x1b[?25l" << std::flush;
  }
  ~Terminal() {
    if (screen_) std::cout << "\x1b[?25h\x1b[?1049l" << std::flush;
    if (keys_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  Terminal(const Terminal&) = delete;
  Terminal& operator=(const Terminal&) = delete;

  void draw(const std::vector<TopLine>& lines, const std::string& footer) const {
    if (!screen_) {  // a pipe or a file: plain frames, one after the other
      for (const auto& line : lines) std::cout << line.text << "\n";
      std::cout << footer << "\n\n" << std::flush;
      return;
    }
    winsize size{};
    const bool known = ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0 && size.ws_row > 0;
    const std::size_t columns = known ? size.ws_col : 80;
    const std::size_t rows = known ? size.ws_row : 24;
    std::string frame = "\x1b[H";
    for (std::size_t i = 0; i < lines.size() && i + 1 < rows; ++i) {
      const std::string cut = lines[i].text.substr(0, columns);
      frame += lines[i].alert ? "\x1b[31m" + cut + "\x1b[0m" : cut;
      frame += "\x1b[K\r\n";
    }
    frame += "\x1b[7m" + footer.substr(0, columns) + "\x1b[0m\x1b[K\x1b[J";
    std::cout << frame << std::flush;
  }

  // Waits until `deadline` for a key; true when the user asked to quit.
  bool quit_requested_before(Clock::time_point deadline) const {
    while (!g_stop) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) return false;
      pollfd input{STDIN_FILENO, POLLIN, 0};
      const int ready = poll(&input, keys_ ? 1 : 0, static_cast<int>(left));
      if (ready > 0 && (input.revents & POLLIN)) {
        char key = 0;
        if (read(STDIN_FILENO, &key, 1) == 1 && (key == 'q' || key == 'Q')) return true;
      }
    }
    return true;
  }

 private:
  bool keys_;
  bool screen_;
  termios saved_{};
};

// status, segments and channels, or why not.
struct Fetched {
  std::optional<TopSample> sample;
  ClientResult failure;
};

Fetched fetch(const std::string& socket) {
  Fetched out;
  TopSample sample;
  for (auto [command, slot] :
       {std::pair{"status", &sample.status}, {"segments", &sample.segments}, {"channels", &sample.channels}}) {
    ClientResult result = request(socket, Json{{"command", command}}, 5'000);
    if (!result.response || !result.response->value("ok", false)) {
      if (result.response)
        result.error = result.response->value("error", Json::object()).value("message", "request failed");
      out.failure = std::move(result);
      return out;
    }
    *slot = std::move(*result.response);
  }
  sample.taken = Clock::now();
  out.sample = std::move(sample);
  return out;
}

std::string footer(const TopOptions& options, const std::string& problem) {
  char clock[16];
  const std::time_t now = std::time(nullptr);
  std::strftime(clock, sizeof clock, "%H:%M:%S", std::localtime(&now));
  char interval[32];
  std::snprintf(interval, sizeof interval, "%.1f", options.interval);
  return std::string(clock) + "  refresh " + interval + " s  q quits" + (problem.empty() ? "" : "  |  " + problem);
}

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;  // no SA_RESTART: poll() returns at once
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

int run_top(const GlobalOptions& global, const TopOptions& options) {
  Fetched first = fetch(global.socket);
  if (!first.sample) {  // nothing to show: fail like every other command
    std::cerr << "cosmicctl: " << first.failure.error << "\n";
    if (first.failure.response) {
      const bool denied =
          first.failure.response->value("error", Json::object()).value("code", "") == "permission_denied";
      return denied ? kExitNoPermission : kExitRejected;
    }
    return first.failure.permission_denied ? kExitNoPermission : kExitUnavailable;
  }
  install_stop_handlers();
  Terminal terminal;
  std::optional<TopSample> previous;
  TopSample current = std::move(*first.sample);
  std::string problem;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.interval));
  for (int frame = 1;; ++frame) {
    terminal.draw(top_frame(current, previous), footer(options, problem));
    if (options.iterations > 0 && frame >= options.iterations) return kExitOk;
    if (terminal.quit_requested_before(Clock::now() + period)) return kExitOk;
    Fetched next = fetch(global.socket);
    if (next.sample) {
      previous = std::move(current);
      current = std::move(*next.sample);
      problem.clear();
    } else {  // keep the last picture and say why it is not moving
      problem = "cosmicd: " + next.failure.error;
    }
  }
}

}  // namespace

CommandRunner add_top_command(CLI::App& app, const GlobalOptions& options) {
  auto* command =
      app.add_subcommand("top", "Live view of segments and channels: rates, drops, residence, misses (q quits)");
  auto top = std::make_shared<TopOptions>();
  command->add_option("--interval", top->interval, "Seconds between refreshes")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  command->add_option("--iterations", top->iterations, "Draw this many frames, then exit (0: until q)")
      ->check(CLI::NonNegativeNumber);
  return [command, &options, top]() -> int {
    if (!command->parsed()) return -1;
    return run_top(options, *top);
  };
}

}  // namespace cosmicctl

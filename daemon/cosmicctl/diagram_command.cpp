// `cosmicctl diagram FILE`: the Event-Channel Diagram of a configuration as SVG (Graphviz's dot)
// or DOT. Offline, channels are coloured by what admission of FILE says; with --socket, by the
// running gateway's verdicts and runtime state, with its live counters and measured residence.
// Compact by default (the details in tooltips); --detail draws every channel as a full table.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "control_client.hpp"
#include "cosmic/config_loader.hpp"
#include "diagram_dot.hpp"
#include "diagram_status.hpp"

extern char** environ;

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

// dot -Tsvg on a temporary file, its output straight to our standard output.
int render_svg(const std::string& dot) {
  char path[] = "/tmp/cosmicctl-diagram-XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) {
    std::perror("cosmicctl: temporary file");
    return kExitUnavailable;
  }
  const bool written = ::write(fd, dot.data(), dot.size()) == static_cast<ssize_t>(dot.size());
  ::close(fd);
  int status = -1;
  pid_t pid = 0;
  std::cout.flush();
  char* argv[] = {const_cast<char*>("dot"), const_cast<char*>("-Tsvg"), path, nullptr};
  const int spawned = written ? posix_spawnp(&pid, "dot", nullptr, nullptr, argv, environ) : -1;
  if (spawned == 0) waitpid(pid, &status, 0);
  ::unlink(path);
  if (spawned != 0) {
    std::cerr << "cosmicctl: cannot run Graphviz's dot (apt-get install graphviz), or use --format dot\n";
    return kExitUnavailable;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return kExitOk;
  // dot's own message (if it wrote one) is already on stderr; say what happened in any case.
  std::cerr << "cosmicctl: Graphviz's dot "
            << (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                    : "failed with exit status " + std::to_string(WEXITSTATUS(status)))
            << " while drawing the diagram; `cosmicctl diagram --format dot` prints the DOT text itself\n";
  return kExitUnavailable;
}

struct DiagramOptions {
  std::string file;
  std::string format = "svg";
  bool detail = false;
};

int run_diagram(const DiagramOptions& o, const GlobalOptions& global, bool live) {
  const auto loaded = cosmic::load_config_file(o.file);
  if (!loaded.ok()) {
    for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
    return kExitConfigError;
  }
  DiagramStatus status;
  std::string title = "Event-Channel Diagram: " + o.file;
  if (live) {
    const auto result = request(global.socket, Json{{"command", "channels"}});
    if (!result.response || !result.response->value("ok", false)) {
      std::cerr << "cosmicctl: " << (result.response ? result.response->dump() : result.error) << "\n";
      return result.permission_denied ? kExitNoPermission : kExitUnavailable;
    }
    status = live_status((*result.response)["channels"]);
    title += " (live: " + global.socket + ")";
  } else {
    status = offline_status(loaded.config);
    title += " (admission offline)";
  }
  const std::string dot =
      render_dot(loaded.config, status, title, o.detail ? DiagramDetail::tables : DiagramDetail::compact);
  if (o.format == "dot") {
    std::cout << dot;
    return kExitOk;
  }
  return render_svg(dot);
}

}  // namespace

CommandRunner add_diagram_command(CLI::App& app, const GlobalOptions& options) {
  auto* command =
      app.add_subcommand("diagram", "Draw the Event-Channel Diagram of a configuration (SVG or DOT on stdout)");
  auto o = std::make_shared<DiagramOptions>();
  command->add_option("FILE", o->file, "Configuration file (YAML)")->required();
  command->add_option("--format", o->format, "svg (needs Graphviz) or dot")
      ->check(CLI::IsMember({"svg", "dot"}))
      ->capture_default_str();
  command->add_flag("--detail", o->detail,
                    "Every channel as a table (subject, QoS list, verdict, notes) instead of one row");
  return [command, o, &options, &app]() -> int {
    if (!command->parsed()) return -1;
    // --socket given (or COSMIC_SOCKET set): the running gateway's view.
    const bool live = app.get_option("--socket")->count() > 0;
    return run_diagram(*o, options, live);
  };
}

}  // namespace cosmicctl

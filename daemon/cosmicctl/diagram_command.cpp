// `cosmicctl diagram FILE`: the Event-Channel Diagram of a configuration as SVG (Graphviz's dot)
// or DOT. Offline, channels are coloured by what admission of FILE says; with --socket, by the
// running gateway's verdicts, with its live counters and measured residence.
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
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"
#include "diagram_dot.hpp"

extern char** environ;

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

std::string micros(double seconds) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.0f us", seconds * 1e6);
  return buffer;
}

// What admission of the file promises: the verdict and the end-to-end bound.
DiagramStatus offline_status(const cosmic::Config& config) {
  DiagramStatus out;
  for (const auto& c : cosmic::admit_all(config).channels) {
    ChannelStatus s{cosmic::to_string(c.verdict), {}};
    const auto& e2e = c.end_to_end;
    if (e2e.latency) {
      std::string promise = "end-to-end <= " + cosmic::format_duration(*e2e.latency);
      if (e2e.reaction_time) promise += " (reaction " + cosmic::format_duration(*e2e.reaction_time) + ")";
      s.notes.push_back(promise);
    }
    for (const auto& r : c.reasons) s.notes.push_back(r);
    out[c.name] = std::move(s);
  }
  return out;
}

// What the running gateway reports (`channels` of the control protocol).
DiagramStatus live_status(const Json& channels) {
  DiagramStatus out;
  for (const auto& c : channels) {
    ChannelStatus s{c.value("verdict", "bound"), {}};
    s.notes.push_back("forwarded " + std::to_string(c.value("forwarded", 0ull)));
    const Json& r = c.value("residence", Json::object());
    if (r.contains("p50_s") && r["p50_s"].is_number()) {
      s.notes.push_back("residence p50 " + micros(r["p50_s"].get<double>()) + ", p99 " + micros(r.value("p99_s", 0.0)));
    }
    for (const auto& seg : c.value("segments", Json::array())) {
      s.notes.push_back(seg.value("segment", "?") + " " + seg.value("role", "?") + ": rx " + std::to_string(seg.value("rx", 0ull)) +
                        ", tx " + std::to_string(seg.value("tx", 0ull)));
    }
    out[c.value("name", "")] = std::move(s);
  }
  return out;
}

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
  const std::string dot = render_dot(loaded.config, status, title);
  if (o.format == "dot") {
    std::cout << dot;
    return kExitOk;
  }
  return render_svg(dot);
}

}  // namespace

CommandRunner add_diagram_command(CLI::App& app, const GlobalOptions& options) {
  auto* command = app.add_subcommand("diagram", "Draw the Event-Channel Diagram of a configuration (SVG or DOT on stdout)");
  auto o = std::make_shared<DiagramOptions>();
  command->add_option("FILE", o->file, "Configuration file (YAML)")->required();
  command->add_option("--format", o->format, "svg (needs Graphviz) or dot")->check(CLI::IsMember({"svg", "dot"}))->capture_default_str();
  return [command, o, &options, &app]() -> int {
    if (!command->parsed()) return -1;
    // --socket given (or COSMIC_SOCKET set): the running gateway's view.
    const bool live = app.get_option("--socket")->count() > 0;
    return run_diagram(*o, options, live);
  };
}

}  // namespace cosmicctl

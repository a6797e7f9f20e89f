// cosmicctl: inspect and steer a running cosmicd, or check a configuration offline.
#include <iostream>
#include <vector>

#include "commands.hpp"
#include "cosmic/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"cosmicctl: control and inspect the cosmic-gateway daemon"};
  app.set_version_flag("--version", "cosmicctl " COSMIC_VERSION);
  app.require_subcommand(1);
  app.fallthrough();
  cosmicctl::GlobalOptions options;
  app.add_flag("--json", options.json, "Machine-readable JSON output");
  std::vector<cosmicctl::CommandRunner> commands;
  app.add_option("--socket", options.socket, "Control socket of the daemon")
      ->capture_default_str()
      ->envname("COSMIC_SOCKET");
  commands.push_back(cosmicctl::add_check_command(app, options));
  commands.push_back(cosmicctl::add_calibrate_command(app, options));
  commands.push_back(cosmicctl::add_diagram_command(app, options));
  commands.push_back(cosmicctl::add_echo_command(app, options));
  commands.push_back(cosmicctl::add_gen_command(app, options));
  commands.push_back(cosmicctl::add_record_command(app, options));
  commands.push_back(cosmicctl::add_security_command(app, options));
  commands.push_back(cosmicctl::add_top_command(app, options));
  commands.push_back(cosmicctl::add_types_command(app, options));
  for (auto& command : cosmicctl::add_daemon_commands(app, options)) commands.push_back(std::move(command));
  for (auto& command : cosmicctl::add_replay_command(app, options)) commands.push_back(std::move(command));
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return cosmicctl::kExitUsage;
  }
  for (const auto& run : commands) {
    const int code = run();
    if (code >= 0) return code;
  }
  return cosmicctl::kExitUsage;
}

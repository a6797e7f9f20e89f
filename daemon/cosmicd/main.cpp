// cosmicd: the cosmic-gateway daemon. Parses the command line and hands over to the daemon.
#include <CLI/CLI.hpp>

#include "cosmic/version.hpp"
#include "daemon.hpp"

int main(int argc, char** argv) {
  CLI::App app{"cosmicd: event-channel gateway between CAN, DDS and LCM"};
  app.set_version_flag("--version", "cosmicd " COSMIC_VERSION);
  cosmicd::DaemonOptions options;
  app.add_option("-c,--config", options.config, "Configuration file")->capture_default_str();
  app.add_option("-s,--socket", options.socket, "Control socket path (overrides gateway.control_socket)");
  app.add_option(
      "--state-file", options.state_file,
      "Where runtime bindings persist (default $STATE_DIRECTORY/bindings.json or /var/lib/cosmicd/bindings.json)");
  app.add_option("--read-group", options.groups.read_group, "Group allowed to read gateway state")
      ->capture_default_str();
  app.add_option("--admin-group", options.groups.admin_group, "Group allowed to bind, unbind and reload")
      ->capture_default_str();
  app.add_option("--report-group", options.groups.report_group,
                 "Group allowed to send FMU runners' reports (fmu_report); default: the read group");
  app.add_option("-l,--log-level", options.log_level, "debug, info, notice, warning or error")
      ->check(CLI::IsMember({"debug", "info", "notice", "warning", "error"}))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 64;
  }
  return cosmicd::run_daemon(options);
}

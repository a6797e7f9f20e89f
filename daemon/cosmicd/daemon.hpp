// The cosmicd process: configuration, gateway, persisted runtime bindings, control socket,
// signals and service-manager notifications, driven by one control loop.
#pragma once

#include <string>

#include "access_policy.hpp"

namespace cosmicd {

struct DaemonOptions {
  std::string config = "/etc/cosmic/cosmicd.yaml";
  std::string socket;      // overrides gateway.control_socket
  std::string state_file;  // default: $STATE_DIRECTORY/bindings.json, else /var/lib/cosmicd/bindings.json
  std::string log_level = "info";
  AccessGroups groups;
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitStartFailure = 1;
inline constexpr int kExitConfigError = 2;

// Runs until SIGTERM/SIGINT; returns the process exit code.
int run_daemon(const DaemonOptions& options);

}  // namespace cosmicd

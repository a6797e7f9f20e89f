// cosmicctl subcommands. Each registers itself on the CLI11 app and runs when selected.
// Exit codes: 0 success, 1 a channel was rejected or the daemon refused, 2 configuration
// errors, 64 usage errors, 69 daemon unreachable.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace cosmicctl {

inline constexpr int kExitOk = 0;
inline constexpr int kExitRejected = 1;
inline constexpr int kExitConfigError = 2;
inline constexpr int kExitUsage = 64;
inline constexpr int kExitUnavailable = 69;

using CommandRunner = std::function<int()>;

struct GlobalOptions {
  bool json = false;
};

CommandRunner add_check_command(CLI::App& app, const GlobalOptions& options);

}  // namespace cosmicctl

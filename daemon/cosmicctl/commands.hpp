// cosmicctl subcommands. Each registers itself on the CLI11 app and runs when selected.
// Exit codes: 0 success, 1 a channel was rejected, the daemon refused or a file could not be
// written, 2 configuration errors, 64 usage errors, 69 daemon unreachable, 75 the daemon is busy
// (try again), 77 permission denied.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace cosmicctl {

inline constexpr int kExitOk = 0;
inline constexpr int kExitRejected = 1;
inline constexpr int kExitConfigError = 2;
inline constexpr int kExitUsage = 64;
inline constexpr int kExitUnavailable = 69;
inline constexpr int kExitTempFail = 75;
inline constexpr int kExitNoPermission = 77;

using CommandRunner = std::function<int()>;

struct GlobalOptions {
  bool json = false;
  std::string socket = "/run/cosmicd/control.sock";
};

CommandRunner add_check_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_calibrate_command(CLI::App& app, const GlobalOptions& options);
std::vector<CommandRunner> add_daemon_commands(CLI::App& app, const GlobalOptions& options);
CommandRunner add_diagram_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_echo_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_gen_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_record_command(CLI::App& app, const GlobalOptions& options);
// `cosmicctl replay FILE ...` and `replay stop NAME` (replay_command.cpp).
std::vector<CommandRunner> add_replay_command(CLI::App& app, const GlobalOptions& options);
// `cosmicctl record info FILE` (record_info.cpp): offline, no daemon.
int run_record_info(const std::string& file, bool json);
CommandRunner add_security_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_top_command(CLI::App& app, const GlobalOptions& options);
CommandRunner add_types_command(CLI::App& app, const GlobalOptions& options);

}  // namespace cosmicctl

// `cosmicctl record start|stop|status` (issue 37, docs/recording.md): the daemon's recording
// started, stopped and shown, through the control protocol's record_start, record_stop and
// record_status; and `record info FILE`, what a recording holds (record_info.cpp).
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "control_client.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

std::string megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MB", static_cast<double>(bytes) / 1e6);
  return text;
}

// The CAN logs (candump -l) of the segments recording.candump lists, when it lists any.
void print_candump(const Json& c) {
  std::string segments;
  for (const auto& s : c.value("segments", Json::array()))
    segments += (segments.empty() ? "" : ", ") + s.get<std::string>();
  if (segments.empty()) return;
  std::cout << "candump: " << segments << ": " << c.value("lines", 0ull) << " lines in " << c.value("files", 0ull)
            << " file(s), dropped " << c.value("dropped", 0ull) << " (" << c.value("dropped_queue_full", 0ull)
            << " queue full, " << c.value("dropped_not_written", 0ull) << " not written)\n";
  for (const auto& file : c.value("files_open", Json::array()))
    std::cout << "candump file: " << file.get<std::string>() << "\n";
  const std::string error = c.value("last_error", "");
  if (!error.empty()) std::cout << "candump last error: " << error << "\n";
}

void print_recording(const Json& r) {
  if (!r.value("configured", false)) {
    std::cout << "recording: not configured (the configuration has no recording: section)\n";
    return;
  }
  const bool active = r.value("active", false);
  std::cout << "recording: " << (active ? "on" : "off") << ", into " << r.value("directory", "") << "\n";
  if (active) std::cout << "file: " << r.value("file", "") << "\n";
  std::string channels;
  for (const auto& c : r.value("channels", Json::array()))
    channels += (channels.empty() ? "" : ", ") + c.get<std::string>();
  std::cout << "channels: " << channels << "\n";
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "%.1f", r.value("compression_ratio", 0.0));
  std::cout << "written: " << r.value("messages", 0ull) << " messages, " << megabytes(r.value("bytes", 0ull)) << " in "
            << r.value("files", 0ull) + (active ? 1 : 0) << " file(s), compression " << ratio << ":1\n";
  const Json& dropped = r["record_dropped"];
  std::cout << "record_dropped: " << dropped.value("queue_full", 0ull) << " queue full, "
            << dropped.value("not_written", 0ull) << " not written, " << dropped.value("invalid", 0ull)
            << " invalid; queue " << megabytes(r.value("queued_bytes", 0ull)) << " of "
            << megabytes(r.value("queue_bytes", 0ull)) << "\n";
  const std::string error = r.value("last_error", "");
  if (!error.empty()) std::cout << "last error: " << error << "\n";
  print_candump(r.value("candump", Json::object()));
}

}  // namespace

CommandRunner add_record_command(CLI::App& app, const GlobalOptions& options) {
  auto* command = app.add_subcommand("record", "Start, stop or show the daemon's recording (MCAP files)");
  command->require_subcommand(1);
  auto* start = command->add_subcommand("start", "Start recording the channels recording.channels selects");
  auto* stop = command->add_subcommand("stop", "Finish the current file and stop recording");
  auto* status = command->add_subcommand("status", "Show the recording: file, counts, drops");
  auto* info = command->add_subcommand("info",
                                       "Show what a recording (an MCAP file) holds: channels, counts, "
                                       "time span, rates, gaps, drops");
  auto file = std::make_shared<std::string>();
  info->add_option("FILE", *file, "An MCAP file cosmicd recorded")->required()->check(CLI::ExistingFile);
  return [command, start, stop, status, info, file, &options]() -> int {
    if (!command->parsed()) return -1;
    if (info->parsed()) return run_record_info(*file, options.json);
    const char* name = start->parsed() ? "record_start" : stop->parsed() ? "record_stop" : "record_status";
    (void)status;
    const ClientResult result = request(options.socket, Json{{"command", name}});
    if (!result.response) {
      std::cerr << "cosmicctl: " << result.error << "\n";
      return result.permission_denied ? kExitNoPermission : kExitUnavailable;
    }
    const Json& response = *result.response;
    if (options.json) std::cout << response.dump(2) << "\n";
    if (!response.value("ok", false)) {
      if (!options.json) print_errors(response);
      return exit_code_for_failure(response);
    }
    if (!options.json) print_recording(response["recording"]);
    return kExitOk;
  };
}

}  // namespace cosmicctl

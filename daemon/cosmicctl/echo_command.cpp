// cosmicctl echo CHANNEL: prints a running channel's events as they arrive, a typed channel's
// decoded (its fields as JSON), an untyped one's contents in hex. It opens a tap on the channel
// (echo_open), reads it every --interval (echo_read) and closes it when done (echo_close); the tap
// is bounded and never slows forwarding, so under load it may miss events, which echo reports.
#include <csignal>
#include <iostream>
#include <memory>
#include <thread>
#include <variant>

#include "commands.hpp"
#include "control_client.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_echo_stop = 0;
void on_echo_signal(int) { g_echo_stop = 1; }

struct EchoOptions {
  std::string channel;
  std::uint64_t count = 0;  // 0: until interrupted
  double interval = 0.1;
  double timeout = 0;  // 0: none
};

// The daemon's answer to `req`, or the exit code of why there is none.
std::variant<Json, int> ask(const GlobalOptions& options, const Json& req) {
  const ClientResult result = request(options.socket, req);
  if (!result.response) {
    std::cerr << "cosmicctl: " << result.error << "\n";
    return result.permission_denied ? kExitNoPermission : kExitUnavailable;
  }
  if (!result.response->value("ok", false)) {
    const Json& error = (*result.response)["error"];
    std::cerr << "cosmicctl: " << error.value("message", std::string("request failed")) << "\n";
    const std::string code = error.value("code", "");
    return code == "permission_denied" ? kExitNoPermission : code == "bad_request" ? kExitUsage : kExitRejected;
  }
  return *result.response;
}

// One event: with --json the event object with the channel's name; otherwise "#SEQUENCE CONTENTS".
void print_event(const EchoOptions& echo, const GlobalOptions& options, Json event) {
  if (options.json) {
    event["channel"] = echo.channel;
    std::cout << event.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
    return;
  }
  const Json& shown = event.contains("contents") ? event["contents"] : event["payload"];
  std::cout << "#" << event.value("sequence", 0u) << " "
            << (shown.is_string() ? shown.get<std::string>()
                                  : shown.dump(-1, ' ', false, Json::error_handler_t::replace))
            << "\n";
}

int run_echo(const EchoOptions& echo, const GlobalOptions& options) {
  auto opened = ask(options, Json{{"command", "echo_open"}, {"name", echo.channel}});
  if (const int* code = std::get_if<int>(&opened)) return *code;
  const Json& open = std::get<Json>(opened);
  const std::uint64_t tap = open["tap"].get<std::uint64_t>();
  // On stderr in either mode: the tap is open from here on (tools wait for this line).
  std::cerr << "echo " << echo.channel << ": "
            << (open["type"].is_string() ? open["type"].get<std::string>() : std::string("untyped (contents in hex)"))
            << std::endl;
  std::signal(SIGINT, on_echo_signal);
  std::signal(SIGTERM, on_echo_signal);
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(echo.timeout));
  std::uint64_t printed = 0, missed = 0;
  int code = kExitOk;
  while (!g_echo_stop && (echo.count == 0 || printed < echo.count)) {
    auto read = ask(options, Json{{"command", "echo_read"}, {"tap", tap}});
    if (const int* failed = std::get_if<int>(&read)) {
      code = *failed;
      break;
    }
    const Json& answer = std::get<Json>(read);
    missed += answer.value("missed", std::uint64_t{0});
    for (const auto& event : answer["events"]) {
      if (echo.count != 0 && printed == echo.count) break;
      print_event(echo, options, event);
      ++printed;
    }
    std::cout << std::flush;
    if (echo.count != 0 && printed == echo.count) break;
    if (echo.timeout > 0 && Clock::now() >= deadline) {
      std::cerr << "cosmicctl: echo " << echo.channel << ": " << printed << " events in " << echo.timeout << " s\n";
      code = echo.count != 0 ? kExitTempFail : kExitOk;
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(echo.interval));  // the polling period, not a wait
  }
  request(options.socket, Json{{"command", "echo_close"}, {"tap", tap}});
  if (missed > 0) std::cerr << "cosmicctl: echo " << echo.channel << ": the tap missed " << missed << " events\n";
  return code;
}

}  // namespace

CommandRunner add_echo_command(CLI::App& app, const GlobalOptions& options) {
  auto echo = std::make_shared<EchoOptions>();
  auto* command = app.add_subcommand("echo", "Print a running channel's events, decoded when the channel is typed");
  command->add_option("CHANNEL", echo->channel, "Channel name")->required();
  command->add_option("--count", echo->count, "Stop after this many events (default: until Ctrl-C)");
  command->add_option("--interval", echo->interval, "Seconds between reads of the tap")
      ->check(CLI::Range(0.01, 10.0))
      ->capture_default_str();
  command->add_option("--timeout", echo->timeout, "Give up after this many seconds (with --count: exit 75)")
      ->check(CLI::Range(0.0, 86400.0));
  return [command, echo, &options]() -> int {
    if (!command->parsed()) return -1;
    return run_echo(*echo, options);
  };
}

}  // namespace cosmicctl

// What cosmicctl's changing commands share (bind, bind --replace, reload, replay): one request
// sent and its answer printed, and the printers of admission verdicts and of a replacement.
#pragma once

#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "control_client.hpp"

namespace cosmicctl {

std::string seconds_as_micros(double seconds);
// A count of nanoseconds as a duration ("10 ms"); "-" for anything but a number.
std::string nanos_text(const nlohmann::json& ns);
// Seconds as a short age: "0.4s ago", "12s ago".
std::string age_text(double seconds);
// A JSON value as text: a string as it is, anything else dumped.
std::string text(const nlohmann::json& value);
// JSON carries UTF-8 only: other bytes get a clear message (naming `what`) instead of an encoder exception.
bool is_utf8(const std::string& what, const std::string& text);

// Each channel's verdict with its reasons and its response-time and latency checks.
void print_verdicts(const nlohmann::json& channels);
// What a replacement changed per channel, and which hops kept their endpoints.
void print_replaced(const nlohmann::json& replaced);
// How a replacement switched over (made before break): the wait and each new publisher's matches.
void print_switch_over(const nlohmann::json& switch_over);

// Registers a subcommand that sends one request and prints the answer.
template <typename Build, typename Print>
CommandRunner add_request_command(CLI::App& app, const GlobalOptions& options, CLI::App* command, Build build,
                                  Print print) {
  (void)app;
  return [command, &options, build, print]() -> int {
    if (!command->parsed()) return -1;
    nlohmann::json req;
    if (const int code = build(req); code != kExitOk) return code;
    const ClientResult result = request(options.socket, req);
    if (!result.response) {
      std::cerr << "cosmicctl: " << result.error << "\n";
      return result.permission_denied ? kExitNoPermission : kExitUnavailable;
    }
    const nlohmann::json& response = *result.response;
    if (options.json) std::cout << response.dump(2) << "\n";
    if (!response.value("ok", false)) {
      if (!options.json) {
        if (response.contains("channels")) print_verdicts(response["channels"]);
        print_errors(response);
      }
      return exit_code_for_failure(response);
    }
    if (!options.json) print(response);
    return kExitOk;
  };
}

}  // namespace cosmicctl

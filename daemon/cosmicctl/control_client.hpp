// A blocking client of the control protocol: one request line out, one response line back.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace cosmicctl {

struct ClientResult {
  std::optional<nlohmann::json> response;
  std::string error;               // why there is no response (daemon unreachable, timeout, garbage)
  bool permission_denied = false;  // the socket refused us (file permissions)
};

// The daemon's answer is returned even when it closed the connection before reading the whole
// request (too_large, busy): that answer says more than "Broken pipe".
ClientResult request(const std::string& socket_path, const nlohmann::json& request, int timeout_ms = 30'000);

// A failed answer's message (and each located error) on standard error.
void print_errors(const nlohmann::json& response);
// The exit code for a failed answer: its error code as cosmicctl's exit codes (commands.hpp).
int exit_code_for_failure(const nlohmann::json& response);

// Offset of the first byte that is not well-formed UTF-8 (JSON carries UTF-8 only), if any.
std::optional<std::size_t> first_invalid_utf8(std::string_view text);

}  // namespace cosmicctl

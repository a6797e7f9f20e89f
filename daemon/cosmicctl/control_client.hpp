// A blocking client of the control protocol: one request line out, one response line back.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace cosmicctl {

struct ClientResult {
  std::optional<nlohmann::json> response;
  std::string error;  // why there is no response (daemon unreachable, timeout, garbage)
  bool permission_denied = false;  // the socket refused us (file permissions)
};

ClientResult request(const std::string& socket_path, const nlohmann::json& request, int timeout_ms = 30'000);

}  // namespace cosmicctl

// One question to a running cosmicd over its control socket (docs/control-protocol.md). Internal.
#pragma once

#include <string>

namespace cosmic::client_detail {

// The verdict of channel `name` ("bound", "degraded", "violated"), or "not_found". COSMIC_OK, or
// COSMIC_E_UNAVAILABLE with the reason in `out` when the gateway cannot be asked.
int query_verdict(const std::string& socket_path, const std::string& name, std::string& out);

}  // namespace cosmic::client_detail

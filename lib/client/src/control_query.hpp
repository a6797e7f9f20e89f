// One question to a running cosmicd over its control socket (docs/control-protocol.md). Internal.
#pragma once

#include <string>
#include <string_view>

namespace cosmic::client_detail {

// The verdict of channel `name` ("bound", "degraded", "violated"), or "not_found". COSMIC_OK, or
// COSMIC_E_UNAVAILABLE with the reason in `out` when the gateway cannot be asked.
int query_verdict(const std::string& socket_path, const std::string& name, std::string& out);

// The verdict in one answer line of the control protocol, read as query_verdict() reads it:
// COSMIC_OK with the verdict, "not_found" or "rejected (...)" in `out`, or COSMIC_E_UNAVAILABLE
// with the reason. Never throws, whatever `reply` holds (fuzz/client_answer_fuzzer.cpp).
int parse_verdict_answer(std::string_view reply, std::string& out);

}  // namespace cosmic::client_detail

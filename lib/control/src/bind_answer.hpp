// Answers of the control protocol (docs/control-protocol.md): a failure, an answer as its line,
// and those of bind and replace requests, built from a BindResult. Pure functions, any thread.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "cosmic/gateway.hpp"

namespace cosmic {

nlohmann::json failure(const std::string& code, const std::string& message);
// The answer line. Texts quoted from files or interfaces may hold invalid UTF-8: replaced, never thrown.
std::string render(const nlohmann::json& response);

// ok, applied, each channel's verdict, and the error when nothing changed.
nlohmann::json bind_answer(const BindResult& result);
// Per replaced channel: what changed, and which hops were kept, added and removed.
nlohmann::json replaced_answer(const BindResult& result);
// A replacement made before break: how long the switch waited, whether it gave up at
// `match_timeout`, and what each new publisher hop had matched.
nlohmann::json switch_over_answer(const BindResult& result, Nanos match_timeout);

}  // namespace cosmic

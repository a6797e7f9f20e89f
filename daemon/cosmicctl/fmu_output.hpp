// How cosmicctl shows FMUs as components (docs/fmu.md): `cosmicctl fmus`, each FMU of the running
// configuration with its runner's last report, and the FMU part of `cosmicctl channel NAME`.
#pragma once

#include <nlohmann/json.hpp>

namespace cosmicctl {

// The `fmus` answer as a table, then per FMU what needs a word: a step overrun that flags its
// output channels, skipped input events, a failed runner's message.
void print_fmus(const nlohmann::json& answer);
// A channel answer's "fmus" (nothing when no FMU publishes or subscribes the channel).
void print_channel_fmus(const nlohmann::json& fmus);

}  // namespace cosmicctl

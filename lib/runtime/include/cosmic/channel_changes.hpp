// What a replacement changes in a channel's definition, one line per field that differs, for
// the log and the control protocol's answer (e.g. "publishers: body-can -> sim").
#pragma once

#include <string>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmic {

// Empty when the definitions are equal.
std::vector<std::string> definition_changes(const ChannelSpec& before, const ChannelSpec& after);

}  // namespace cosmic

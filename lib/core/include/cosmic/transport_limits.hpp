// What each transport accepts, in one place: the configuration loader, `cosmicctl check` and
// the adapters all use these, so a name the configuration accepts is never refused by a
// transport later (where the failure would only show at run time). Pure constants and checks.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/model.hpp"

namespace cosmic {

// Channel and segment names: [A-Za-z0-9_.-], 1 to this many characters.
inline constexpr std::size_t kMaxNameLength = 64;
// LCM refuses longer channel names (LCM_MAX_CHANNEL_NAME_LENGTH in lcm.h).
inline constexpr std::size_t kLcmMaxChannelName = 63;
// A network interface name (IFNAMSIZ - 1).
inline constexpr std::size_t kMaxInterfaceName = 15;

// Why a segment of type `type` cannot carry a channel named `channel`, if it cannot.
inline std::optional<std::string> transport_name_problem(SegmentType type, std::string_view channel) {
  if (type == SegmentType::lcm && channel.size() > kLcmMaxChannelName) {
    return "LCM channel names have at most " + std::to_string(kLcmMaxChannelName) + " characters, '" +
           std::string(channel.substr(0, 16)) + "...' has " + std::to_string(channel.size());
  }
  return std::nullopt;
}

}  // namespace cosmic

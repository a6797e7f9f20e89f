// What each transport accepts, in one place: the configuration loader, `cosmicctl check` and
// the adapters all use these, so a name the configuration accepts is never refused by a
// transport later (where the failure would only show at run time). Pure constants and checks.
#pragma once

#include <cstddef>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/model.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// Channel and segment names: [A-Za-z0-9_.-], 1 to this many characters.
inline constexpr std::size_t kMaxNameLength = 64;
// LCM refuses longer channel names (LCM_MAX_CHANNEL_NAME_LENGTH in lcm.h).
inline constexpr std::size_t kLcmMaxChannelName = 63;
// A network interface name (IFNAMSIZ - 1).
inline constexpr std::size_t kMaxInterfaceName = 15;

// Whether a segment of type `type` can carry a channel named `channel` (the error says why not).
inline Result<void> check_transport_name(SegmentType type, std::string_view channel) {
  if (type != SegmentType::lcm) return {};
  // A NUL ends the name on the wire (what follows would become payload for other subscribers);
  // control characters would be written into logs. The name itself is not echoed here.
  for (const char c : channel) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char shown[8];
      std::snprintf(shown, sizeof shown, "0x%02X", static_cast<unsigned char>(c));
      return Error{std::string("LCM channel names hold no control characters; this one has ") + shown};
    }
  }
  if (channel.size() > kLcmMaxChannelName) {
    return Error{"LCM channel names have at most " + std::to_string(kLcmMaxChannelName) + " characters, '" +
                 std::string(channel.substr(0, 16)) + "...' has " + std::to_string(channel.size())};
  }
  return {};
}

// Whether `name` can be a network interface name (CAN `interface`, DDS `interfaces`; the error
// says why not): 1 to kMaxInterfaceName characters of [A-Za-z0-9_.@-], not "." or "..". Linux refuses
// '/', ':' and white space itself; the rest of what it would take (quotes, control characters)
// no interface of a real system has, and the gateway copies the name into logs and generated code.
inline Result<void> check_interface_name(std::string_view name) {
  if (name.empty()) return Error{std::string("empty interface name")};
  if (name.size() > kMaxInterfaceName) {
    return Error{"interface name '" + std::string(name.substr(0, 20)) + (name.size() > 20 ? "..." : "") +
                 "' is too long (at most " + std::to_string(kMaxInterfaceName) + " characters)"};
  }
  if (name == "." || name == "..") return Error{"'" + std::string(name) + "' is not an interface name"};
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '.' || c == '@' || c == '-';
    if (!ok) {
      char shown[8];
      std::snprintf(shown, sizeof shown, c > ' ' && c < 0x7f ? "'%c'" : "0x%02X", static_cast<unsigned char>(c));
      return Error{std::string("interface names hold letters, digits, '_', '.', '@' and '-' only; this one has ") +
                   shown};
    }
  }
  return {};
}

}  // namespace cosmic

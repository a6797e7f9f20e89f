// LCM provider URLs, parsed once and canonically (issue 22, item 9): the configuration refuses
// every spelling LCM would read differently from what it says (LCM reads the port with atoi, so
// ":7667/", ":7667 " and ":0x1df3" would all reach some port while looking like another), and
// the one-network check compares what is actually bound. Pure; any thread.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/result.hpp"

namespace cosmic {

inline constexpr std::uint16_t kLcmDefaultPort = 7667;

struct LcmUrl {
  bool memq = false;  // memq://: in-process, private to each LCM instance
  std::string group;  // udpm: IPv4 multicast group, dotted decimal as written
  std::uint16_t port = kLcmDefaultPort;
  std::optional<unsigned> ttl;            // ?ttl=N (0..255)
  std::optional<unsigned> recv_buf_size;  // ?recv_buf_size=BYTES
};

// `url` parsed: "memq://", or "udpm://A.B.C.D[:PORT][?ttl=N][&recv_buf_size=N]" (bare "udpm://" is
// LCM's default, 239.255.76.67:7667) with a multicast
// group (224.0.0.0/4), a decimal port 1..65535, decimal option values and nothing else. Otherwise
// the reason (one line; control characters shown as \xNN).
Result<LcmUrl> parse_lcm_url(std::string_view url);

}  // namespace cosmic

// What authentication costs on this machine, measured (issue 36, item 5; `cosmicctl calibrate`):
// an LCM segment's trailer signed and checked for messages of a given size, each run timed alone
// with the steady clock. The worst of the two per message is what one hop's cryptography adds
// inside the gateway (a sender signs, a receiver checks); `auth.cost` of the segment carries the
// figure into admission.
//
// Threads: blocks its caller for `runs` signs and checks; no shared state, any thread.
#pragma once

#include <cstddef>

#include "cosmic/units.hpp"

namespace cosmic {

struct AuthTiming {
  std::size_t message_bytes = 0;
  std::size_t runs = 0;
  Nanos p50{0}, p99{0}, p999{0}, max{0};  // per message: the slower of signing and checking it
};

AuthTiming time_lcm_auth(std::size_t message_bytes, std::size_t runs);

}  // namespace cosmic

// What authentication costs on this machine, measured (issue 36, item 5; `cosmicctl calibrate`):
// an LCM segment's trailer signed and checked for messages of a given size, a CAN hop's SecOC
// frames protected and verified, each run timed alone with the steady clock. The worst of the two per message is what
// one hop's cryptography adds inside the gateway (a sender signs, a receiver checks); `auth.cost` of the segment
// carries the figure into admission.
//
// Threads: blocks its caller for `runs` signs and checks; no shared state, any thread.
#pragma once

#include <cstddef>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic {

struct AuthTiming {
  std::size_t message_bytes = 0;
  std::size_t runs = 0;
  Nanos p50{0}, p99{0}, p999{0}, max{0};  // per message: the slower of signing and checking it
};

// The figures of `samples` (one per message of `message_bytes`; sorted in place): what the timings
// below return, for measurements made elsewhere (a DDS hop's cryptography, cosmic/dds_security_timing.hpp).
AuthTiming timing_summary(std::size_t message_bytes, std::vector<Nanos>& samples);

AuthTiming time_lcm_auth(std::size_t message_bytes, std::size_t runs);

// A CAN hop's SecOC (cosmic/secoc.hpp): frames of `data_bytes` protected and verified with a MAC of
// `mac_bits` and a truncated freshness of `freshness_bits`; per frame the slower of the two.
AuthTiming time_secoc(std::size_t data_bytes, unsigned mac_bits, unsigned freshness_bits, std::size_t runs);

}  // namespace cosmic

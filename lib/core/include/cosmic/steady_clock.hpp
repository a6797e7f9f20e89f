// The one clock of the forwarding path: residences, deadlines, rates and health are measured on
// the steady (monotonic) clock in Nanos since its epoch. Any thread; no state.
#pragma once

#include <chrono>

#include "cosmic/units.hpp"

namespace cosmic {

inline Nanos steady_now() noexcept {
  return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch());
}

}  // namespace cosmic

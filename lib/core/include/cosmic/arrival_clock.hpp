// Kernel arrival timestamps (SO_TIMESTAMPNS, SO_TIMESTAMP, DDS reception timestamps) are taken on
// the realtime clock; the router measures residence on the steady clock. These helpers move a
// realtime arrival onto the steady clock by the offset between the two clocks read now, so a
// residence starts when the kernel took the packet, not when a user-space thread got to it.
// Pure arithmetic over two clock reads; any thread.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>

#include "cosmic/units.hpp"

namespace cosmic {

// `arrival_realtime_ns` (ns since the epoch, realtime clock) as a steady-clock instant. A
// timestamp in the future (clock stepped) or absent (0) gives `steady_now`; one older than
// `max_age` is clamped to it (a stepped clock must not invent a huge residence).
inline Nanos steady_arrival(std::int64_t arrival_realtime_ns, Nanos steady_now, std::int64_t realtime_now_ns,
                            Nanos max_age = std::chrono::seconds(1)) {
  if (arrival_realtime_ns <= 0) return steady_now;
  const std::int64_t waited = std::clamp<std::int64_t>(realtime_now_ns - arrival_realtime_ns, 0, max_age.count());
  return steady_now - Nanos(waited);
}

// The realtime clock now, in ns since the epoch.
inline std::int64_t realtime_now_ns() {
  using namespace std::chrono;
  return duration_cast<Nanos>(system_clock::now().time_since_epoch()).count();
}

// The same with both clocks read now.
inline Nanos steady_arrival_now(std::int64_t arrival_realtime_ns) {
  using namespace std::chrono;
  const Nanos steady = duration_cast<Nanos>(steady_clock::now().time_since_epoch());
  return steady_arrival(arrival_realtime_ns, steady, realtime_now_ns());
}

}  // namespace cosmic

// How much of the time sends take, judged over windows, with hysteresis: whether a sender is
// loaded. An egress lane keeps one for its sends (whoever sends), and each ingress thread one for
// the sends it made itself (EgressLane::push_or_send), so that a receive thread feeding several
// lanes is judged by their sum.
//
// A send's time is wall time, with the preemptions by the threads it wakes: DDS -> cosmicd -> DDS
// (scripts/bench relay-rates, 2 CPUs), direct sends took a median 19% of 10 ms windows at 10 kHz,
// 32% (at most 82%) at 20 kHz and 56% at saturation. So a sender is loaded from 60% until it falls
// to 35%, and at once by one send as long as the residence bound (gateway.residence_bound: a
// congested network, a blocking transport; the receive thread must not wait for it again).
//
// Not thread-safe: one thread at a time (the lane hands it from sender to sender under its mutex).
#pragma once

#include <cstdint>

#include "cosmic/units.hpp"

namespace cosmic {

class SendDuty {
 public:
  static constexpr Nanos kWindow{10'000'000};
  static constexpr std::int64_t kLoadedPercent = 60;
  static constexpr std::int64_t kUnloadedPercent = 35;

  // Counts one send (or one batch) from `started` to `ended`; one of `slow` or longer loads.
  void note(Nanos started, Nanos ended, Nanos slow) noexcept {
    busy_ += ended - started;
    judge(ended);
    // After judging: a window that ends with a slow send does not clear it.
    if (ended - started >= slow) loaded_ = true;
  }
  // Without a send at `now`: a window that has passed is judged by the sends it had (none while
  // a loaded sender leaves them to others), so a sender that stopped sending is loaded no longer.
  void note_idle(Nanos now) noexcept { judge(now); }
  bool loaded() const noexcept { return loaded_; }

 private:
  void judge(Nanos now) noexcept {
    const Nanos span = now - window_start_;
    if (span < kWindow) return;
    const std::int64_t percent = busy_.count() * 100 / span.count();
    if (percent >= kLoadedPercent) {
      loaded_ = true;
    } else if (percent <= kUnloadedPercent) {
      loaded_ = false;
    }
    window_start_ = now;
    busy_ = Nanos(0);
  }

  Nanos window_start_{0};
  Nanos busy_{0};
  bool loaded_ = false;
};

}  // namespace cosmic

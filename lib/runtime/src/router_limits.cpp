// router_limits(): how gateway.residence_bound and gateway.realtime turn into the router's lane
// threads (declared in cosmic/gateway.hpp; used by the gateway and by `cosmicctl calibrate`).
#include <algorithm>

#include "cosmic/gateway.hpp"
#include "cosmic/thread_policy.hpp"

namespace cosmic {

RouterLimits router_limits(const GatewaySpec& gateway) {
  RouterLimits limits;
  limits.residence_bound = gateway.residence_bound;
  const RealtimeSpec& rt = gateway.realtime;
  const int priority[3] = {rt.hrt_priority, rt.srt_priority, rt.nrt_priority};
  for (std::size_t c = 0; c < 3; ++c) {
    limits.lane_threads[c].fifo_priority = priority[c];
    limits.lane_threads[c].cpus = rt.cpus.of(static_cast<ChannelClass>(c));
  }
  // Time-shared NRT lanes run at nice 10 so that they yield to time-shared HRT and SRT lanes. Once
  // both of those run SCHED_FIFO they need no such help, and nice 10 only starves the NRT lanes
  // against the receive threads that feed them (nice 0): under an overload those took nearly all
  // the CPU to receive events that then found their lane full (scripts/bench at saturation:
  // LCM -> cosmicd -> DDS forwarded 27k events/s with the NRT lane at nice 10, 86k at nice 0).
  // Configured is not granted: without the privilege HRT and SRT lanes stay time-shared.
  if (rt.hrt_priority > 0 && rt.srt_priority > 0 && sched_fifo_permitted(std::max(rt.hrt_priority, rt.srt_priority)))
    limits.lane_threads[static_cast<std::size_t>(ChannelClass::nrt)].nice = 0;
  return limits;
}

}  // namespace cosmic

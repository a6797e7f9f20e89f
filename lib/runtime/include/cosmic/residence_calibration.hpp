// Calibration of gateway.residence_bound on this machine (`cosmicctl calibrate`).
//
// Runs the gateway's own forwarding plane (router, ingress checks, payload pool, egress lanes
// under the configuration's gateway.realtime policy) between two null transports: HRT events at a
// fixed rate, first on an otherwise idle gateway, then while a time-shared thread floods an NRT
// channel to the same egress segment as fast as it can. Residence is what the running gateway
// measures per hop (ingress to the return of send()), taken from the router's own histograms.
// Transport send costs are not included (the null transport returns at once): they are what
// `cosmicctl channel` shows per hop in the running gateway.
//
// Threads: calibrate_residence() blocks its caller for about two phase durations and runs its own
// producer threads; no global state, any thread may call it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

struct CalibrationOptions {
  Nanos phase_duration{Nanos(2'000'000'000)};  // each of the two phases
  double hrt_rate_hz = 1000;                   // HRT events per second
  std::size_t hrt_payload = 8;                 // bytes
  std::size_t flood_payload = 1024;            // bytes of the NRT flood's events
};

struct CalibrationPhase {
  std::string name;                       // "idle" or "nrt-flood"
  std::uint64_t hrt_events = 0;           // HRT events offered
  std::uint64_t hrt_sent = 0;             // HRT events the lane sent (the histogram's events)
  Nanos p50{0}, p99{0}, p999{0}, max{0};  // HRT residence
  std::uint64_t residence_miss = 0;       // HRT events above the configured residence_bound
  std::uint64_t flood_offered = 0;        // NRT events the flood thread offered
  std::uint64_t flood_sent = 0;
  std::uint64_t flood_queue_full = 0;
};

struct CalibrationResult {
  std::vector<CalibrationPhase> phases;
  Nanos residence_bound{0};                  // gateway.residence_bound of the configuration
  Nanos worst_p999{0};                       // the larger p99.9 of the phases
  std::vector<std::string> thread_problems;  // realtime policy parts this process could not get
  bool bound_covers_p999() const { return residence_bound >= worst_p999; }
};

CalibrationResult calibrate_residence(const GatewaySpec& gateway, const CalibrationOptions& options = {});

}  // namespace cosmic

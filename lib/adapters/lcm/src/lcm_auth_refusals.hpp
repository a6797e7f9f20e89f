// What an authenticated LCM segment does with a message that failed its check (cosmic/lcm_auth.hpp):
// counts it by kind (the segment's `unauthenticated` and `replayed`) and logs the first of each
// kind, then one every 10 s at most, with where it came from, so that an attack or a misconfigured
// peer leaves a trace and not a flood of lines. Internal to the LCM adapter.
//
// Threads: refuse() on the segment's receive thread only; report() from any thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "cosmic/lcm_auth.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic::lcm_detail {

// The segment's checker: its key, the keys it also accepts (a key change), its window.
Result<LcmAuthVerifier> make_verifier(const LcmAuthSpec& auth);

class LcmAuthRefusals {
 public:
  LcmAuthRefusals(std::string prefix, Nanos window, Logger& log)
      : prefix_(std::move(prefix)), window_(window), log_(log) {}

  // Counts `checked` (not authentic) of LCM channel `channel` from `from` at `now`; the problem
  // to report for the channel.
  InboundProblem refuse(const std::string& channel, const std::string& from, const LcmAuthCheck& checked, Nanos now);
  // The counters, as the segment's transport counters.
  void report(AdapterStatistics& statistics) const;

 private:
  const std::string prefix_;
  const Nanos window_;
  Logger& log_;
  Nanos last_unauthenticated_log_ = Nanos::min();  // receive thread
  Nanos last_replayed_log_ = Nanos::min();
  std::atomic<std::uint64_t> unauthenticated_{0};
  std::atomic<std::uint64_t> replayed_{0};
};

}  // namespace cosmic::lcm_detail

// The frames on a CAN bus that no binding and no background declaration explains (issue 19,
// item 2): admission's analysis holds only for the traffic it knows, so the adapter watches the
// whole bus on a second, unfiltered socket and counts every frame it cannot explain, by
// identifier, with its rate. Bounded: at most kMaxIdentifiers identifiers are tracked, the rest
// are summed in `others`.
//
// Threads: count() and expire() from the adapter's receive thread, snapshot() from any thread;
// one mutex, held for a map update (never across I/O).
#pragma once

#include <linux/can.h>

#include <cstdint>
#include <map>
#include <vector>

#include "cosmic/mutex.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/units.hpp"

namespace cosmic::can_census {

class BusCensus {
 public:
  static constexpr std::size_t kMaxIdentifiers = 64;
  static constexpr Nanos kWindow{1'000'000'000};  // rates are measured over one second

  // One frame (identifier as read, flags included) that nothing explains, received at `now`.
  void count(canid_t can_id, Nanos now);
  // The identifiers seen, lowest arbitration key first, with the rate of the last full window
  // (0 once an identifier has been silent for two windows).
  std::vector<UnexplainedFrames> snapshot(Nanos now) const;
  std::uint64_t others() const;
  void clear();

 private:
  struct Tally {
    std::uint64_t total = 0;
    std::uint64_t in_window = 0;
    Nanos window_start{0};
    Nanos last_seen{0};
    double rate_hz = 0;  // of the last full window
  };
  mutable Mutex mutex_;
  std::map<std::uint32_t, Tally> tallies_ COSMIC_GUARDED_BY(mutex_);  // by arbitration key
  std::uint64_t others_ COSMIC_GUARDED_BY(mutex_) = 0;
};

}  // namespace cosmic::can_census

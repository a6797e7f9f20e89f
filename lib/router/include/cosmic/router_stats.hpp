// Counters of the router, updated lock-free from adapter threads and the router thread and read
// by the control thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic {

enum class DropReason : std::size_t { expired, rate, queue_full, duplicate, decode_error, no_route, send_failed };
inline constexpr std::size_t kDropReasonCount = 7;
const char* to_string(DropReason reason);

struct SegmentCounters {
  std::atomic<std::uint64_t> rx{0};
  std::atomic<std::uint64_t> tx{0};
  std::array<std::atomic<std::uint64_t>, kDropReasonCount> dropped{};
  void drop(DropReason reason) { dropped[static_cast<std::size_t>(reason)].fetch_add(1, std::memory_order_relaxed); }
};

// Log-linear histogram of durations (4 buckets per power of two of nanoseconds), fixed size.
class LatencyHistogram {
 public:
  void record(Nanos value);
  // Upper bound of the bucket holding quantile q (0..1); 0 when empty.
  Nanos quantile(double q) const;
  Nanos max() const { return Nanos(max_.load(std::memory_order_relaxed)); }
  std::uint64_t count() const;

 private:
  static constexpr std::size_t kBuckets = 4 * 48;
  static std::size_t bucket_of(std::uint64_t ns);
  static std::uint64_t upper_bound_of(std::size_t bucket);
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::int64_t> max_{0};
};

// Plain copies for reporting.
struct SegmentCountersSnapshot {
  std::string segment;
  std::uint64_t rx = 0;
  std::uint64_t tx = 0;
  std::array<std::uint64_t, kDropReasonCount> dropped{};
};

struct ChannelStatsSnapshot {
  std::string name;
  std::vector<SegmentCountersSnapshot> segments;
  Nanos residence_p50{0};
  Nanos residence_p99{0};
  Nanos residence_max{0};
  std::uint64_t forwarded = 0;  // events dispatched to at least one subscriber segment
};

}  // namespace cosmic

// Counters of the router, updated lock-free from ingress (adapter) threads and the egress lane
// threads, and read by the control thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/units.hpp"

namespace cosmic {

// expired: temp_validity reached; rate: beyond the channel's rate; queue_full: the egress lane or
// the transport could not take it; duplicate: seen before or a loop copy; decode_error: the
// bytes were not an event; no_route: not bound for that direction; send_failed: the transport
// refused it; invalid: a header field out of range (negative or absurd age, foreign subject,
// our own origin); oversize: larger than the channel's admitted payload; corrupt: a frame whose
// end-to-end CRC or counter value is wrong (cosmic/e2e_protection.hpp).
enum class DropReason : std::size_t {
  expired,
  rate,
  queue_full,
  duplicate,
  decode_error,
  no_route,
  send_failed,
  invalid,
  oversize,
  out_of_range,  // a typed event's value its hop's representation cannot hold (on_range: drop)
  corrupt,
  unauthenticated,  // an authenticated hop's message without a valid tag (docs/security.md)
  replayed          // ... with a valid tag, sent before or outside the freshness window
};
inline constexpr std::size_t kDropReasonCount = 13;
const char* to_string(DropReason reason);

struct SegmentCounters {
  std::atomic<std::uint64_t> rx{0};
  std::atomic<std::uint64_t> tx{0};
  std::array<std::atomic<std::uint64_t>, kDropReasonCount> dropped{};
  // A hop with end-to-end protection: events its publisher sent that never arrived (gaps in the
  // counter), and the gaps longer than the channel's omission_degree.
  std::atomic<std::uint64_t> omitted{0};
  std::atomic<std::uint64_t> omission_excess{0};
  void drop(DropReason reason) { dropped[static_cast<std::size_t>(reason)].fetch_add(1, std::memory_order_relaxed); }
};

// Log-linear histogram of durations (8 buckets per power of two of nanoseconds, so a quantile's
// upper bound is within 12.5% of the value: 16.4-20.5 us is split into 2 us steps), fixed size.
class LatencyHistogram {
 public:
  void record(Nanos value);
  // Upper bound of the bucket holding quantile q (0..1); 0 when empty.
  Nanos quantile(double q) const;
  Nanos max() const { return Nanos(max_.load(std::memory_order_relaxed)); }
  std::uint64_t count() const;
  // Per-bucket counts (not cumulative) and each bucket's inclusive upper bound in ns, for
  // exporters that re-bucket (Prometheus).
  static constexpr unsigned kSubBucketBits = 3;
  static constexpr std::size_t kSubBuckets = std::size_t{1} << kSubBucketBits;
  static constexpr std::size_t kBuckets = kSubBuckets * 48;  // up to 2^50 ns
  std::uint64_t bucket_count(std::size_t bucket) const { return buckets_[bucket].load(std::memory_order_relaxed); }
  static std::uint64_t upper_bound_of(std::size_t bucket);

 private:
  static std::size_t bucket_of(std::uint64_t ns);
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::int64_t> max_{0};
};

// Runtime verification of one egress hop (channel x subscriber segment), written by that
// segment's lane thread. Residence runs from the kernel's arrival of the event to the return of
// the transport's send(); age at egress is the age the event arrived with plus that residence.
struct EgressStats {
  LatencyHistogram residence;
  std::atomic<std::uint64_t> residence_miss{0};  // residence > gateway.residence_bound
  std::atomic<std::uint64_t> deadline_miss{0};   // age at egress > the channel's reaction_time
};

// Plain copies for reporting.
struct HopRuntimeSnapshot {
  std::uint64_t events = 0;  // residences recorded
  Nanos residence_p50{0};
  Nanos residence_p99{0};
  Nanos residence_p999{0};
  Nanos residence_max{0};
  std::uint64_t residence_miss = 0;
  std::uint64_t deadline_miss = 0;
  std::vector<std::uint64_t> residence_buckets;  // LatencyHistogram buckets, trimmed after the last non-empty one
};

struct SegmentCountersSnapshot {
  std::string segment;
  std::uint64_t rx = 0;
  std::uint64_t tx = 0;
  std::array<std::uint64_t, kDropReasonCount> dropped{};
  std::uint64_t omitted = 0;
  std::uint64_t omission_excess = 0;
  std::optional<HopRuntimeSnapshot> egress;  // set on the channel's subscriber segments
};

// Runtime state of a channel, judged against what admission promised (Gateway, control thread):
// bound: no miss within the clean interval; violated: an HRT hop missed its residence bound or
// its reaction time (SRT channels count misses but stay bound: they were promised no bound).
enum class RuntimeState { bound, violated };
const char* to_string(RuntimeState state);

// The miss counters of one channel summed over its egress hops: what the run-time check reads
// every tick (cheap, unlike a full snapshot with its histograms).
struct ChannelMisses {
  std::string name;
  std::uint64_t residence_miss = 0;
  std::uint64_t deadline_miss = 0;
  std::uint64_t omission_excess = 0;  // over its publisher hops (SegmentCounters)
};

struct ChannelStatsSnapshot {
  std::string name;
  std::vector<SegmentCountersSnapshot> segments;
  Nanos residence_p50{0};  // over every egress hop of the channel
  Nanos residence_p99{0};
  Nanos residence_p999{0};
  Nanos residence_max{0};
  std::uint64_t residence_miss = 0;  // sums over the egress hops
  std::uint64_t deadline_miss = 0;
  std::uint64_t forwarded = 0;                       // events accepted and queued for at least one subscriber segment
  RuntimeState runtime_state = RuntimeState::bound;  // filled in by the Gateway
  std::uint64_t violations = 0;                      // episodes since the channel was bound (Gateway)
};

}  // namespace cosmic

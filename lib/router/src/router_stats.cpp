#include "cosmic/router_stats.hpp"

#include <bit>

namespace cosmic {

const char* to_string(DropReason reason) {
  switch (reason) {
    case DropReason::expired:
      return "expired";
    case DropReason::rate:
      return "rate";
    case DropReason::queue_full:
      return "queue_full";
    case DropReason::duplicate:
      return "duplicate";
    case DropReason::decode_error:
      return "decode_error";
    case DropReason::no_route:
      return "no_route";
    case DropReason::send_failed:
      return "send_failed";
    case DropReason::invalid:
      return "invalid";
    case DropReason::oversize:
      return "oversize";
    case DropReason::out_of_range:
      return "out_of_range";
    case DropReason::corrupt:
      return "corrupt";
    case DropReason::unauthenticated:
      return "unauthenticated";
    case DropReason::replayed:
      return "replayed";
  }
  return "?";
}

const char* to_string(RuntimeState state) { return state == RuntimeState::violated ? "violated" : "bound"; }

// Values below kSubBuckets have a bucket each; above, a power of two 2^e (e >= kSubBucketBits)
// is split into kSubBuckets equal buckets by the kSubBucketBits bits after its leading one.
std::size_t LatencyHistogram::bucket_of(std::uint64_t ns) {
  if (ns < kSubBuckets) return static_cast<std::size_t>(ns);
  const unsigned exponent = 63u - static_cast<unsigned>(std::countl_zero(ns));  // >= kSubBucketBits
  const std::uint64_t mantissa = (ns >> (exponent - kSubBucketBits)) & (kSubBuckets - 1);
  const std::size_t bucket = kSubBuckets * (exponent - kSubBucketBits + 1) + mantissa;
  return bucket < kBuckets ? bucket : kBuckets - 1;
}

std::uint64_t LatencyHistogram::upper_bound_of(std::size_t bucket) {
  if (bucket < kSubBuckets) return bucket;
  const std::size_t exponent = bucket / kSubBuckets + kSubBucketBits - 1;
  const std::uint64_t mantissa = bucket % kSubBuckets;
  return ((kSubBuckets + mantissa + 1) << (exponent - kSubBucketBits)) - 1;
}

void LatencyHistogram::record(Nanos value) {
  const std::int64_t ns = value.count() < 0 ? 0 : value.count();
  buckets_[bucket_of(static_cast<std::uint64_t>(ns))].fetch_add(1, std::memory_order_relaxed);
  std::int64_t seen = max_.load(std::memory_order_relaxed);
  while (ns > seen && !max_.compare_exchange_weak(seen, ns, std::memory_order_relaxed)) {
  }
}

std::uint64_t LatencyHistogram::count() const {
  std::uint64_t total = 0;
  for (const auto& b : buckets_) total += b.load(std::memory_order_relaxed);
  return total;
}

Nanos LatencyHistogram::quantile(double q) const {
  const std::uint64_t total = count();
  if (total == 0) return Nanos(0);
  const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(total - 1)) + 1;
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i].load(std::memory_order_relaxed);
    if (seen >= rank) return Nanos(static_cast<std::int64_t>(std::min<std::uint64_t>(upper_bound_of(i), max_.load())));
  }
  return max();
}

}  // namespace cosmic

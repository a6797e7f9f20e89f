// The /metrics document (every metric is described in docs/metrics.md). A pure function of one
// snapshot, so unit tests drive it without a gateway or a socket. Any thread.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "metrics_exposition.hpp"
#include "metrics_snapshot.hpp"

namespace cosmicd {

std::string render_metrics(const MetricsSnapshot& snapshot, ExpositionFormat format);

// Finite upper bounds, in seconds, of the exported residence histogram (then +Inf).
const std::vector<double>& residence_bucket_bounds();

// Folds LatencyHistogram's per-bucket counts (bucket i holds durations up to
// LatencyHistogram::upper_bound_of(i) ns) into cumulative counts over residence_bucket_bounds()
// plus +Inf. A source bucket is counted where its upper bound fits, so an exported bucket never
// claims an event faster than it was.
std::vector<std::uint64_t> rebucket_residence(const std::vector<std::uint64_t>& source);

}  // namespace cosmicd

#include "cosmic/can_timing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace cosmic {
namespace {

// Arbitration-phase bits of a CAN FD frame before the data phase starts (SOF, identifier,
// SRR/IDE for extended, RRS, FDF, res, BRS), subject to dynamic stuffing.
constexpr std::uint32_t kFdArbitrationBitsStandard = 17;
constexpr std::uint32_t kFdArbitrationBitsExtended = 36;
// ACK slot, ACK delimiter, end of frame and interframe space, at the nominal rate.
constexpr std::uint32_t kFdTrailerBits = 12;
// Analysis gives up (unbounded) past this horizon: no CAN deadline is anywhere near it.
constexpr std::int64_t kHorizonNs = 100'000'000'000;

std::int64_t error_overhead(std::int64_t interval, const CanBusTiming& timing, std::int64_t largest_hep_frame) {
  if (timing.errors.max_per_window == 0 || timing.errors.window.count() <= 0) return 0;
  const std::int64_t windows = ceil_div(interval, timing.errors.window.count());
  return windows * timing.errors.max_per_window * (timing.error_frame_time.count() + largest_hep_frame);
}

// Streams of one bus sorted by threshold T - J: a higher-priority stream k is released once in
// an interval x (w + J_k + offset <= T_k) exactly when x + offset <= T_k - J_k, so only the
// streams at the front of this list, below the threshold, need their ceiling computed.
struct Release {
  std::int64_t threshold;  // T - J
  std::size_t position;    // place in priority order
  std::int64_t transmission;
  std::int64_t period;
  std::int64_t jitter;
};

// What the recurrences of one stream need: itself, and its higher-priority streams as the
// positions before `first_of_level` in priority order.
struct StreamContext {
  const CanStream& self;
  std::size_t first_of_level = 0;
  std::int64_t blocking = 0;           // B: longest frame of equal or lower priority
  std::int64_t largest_hep_frame = 0;  // longest frame of higher or equal priority
  std::int64_t higher_frames = 0;      // sum of C over hp(m): each released at least once
  const std::vector<Release>* releases = nullptr;
};

// sum over hp(m) of ceil((x + J_k + offset) / T_k) * C_k, x + J_k + offset > 0.
std::int64_t interference(const StreamContext& ctx, std::int64_t x, std::int64_t offset) {
  std::int64_t sum = ctx.higher_frames;
  for (const Release& k : *ctx.releases) {
    if (k.threshold >= x + offset) break;
    if (k.position >= ctx.first_of_level) continue;
    sum += (ceil_div(x + k.jitter + offset, k.period) - 1) * k.transmission;
  }
  return sum;
}

// Length of the priority level-m busy period; nullopt when it does not end within the horizon.
std::optional<std::int64_t> busy_period(const StreamContext& ctx, const CanBusTiming& timing) {
  std::int64_t t = ctx.self.transmission.count();
  while (true) {
    const std::int64_t next =
        ctx.blocking + error_overhead(t, timing, ctx.largest_hep_frame) +
        ceil_div(t + ctx.self.jitter.count(), ctx.self.period.count()) * ctx.self.transmission.count() +
        interference(ctx, t, 0);
    if (next == t) return t;
    if (next > kHorizonNs) return std::nullopt;
    t = next;
  }
}

// Queuing delay w_m(q) of instance q. `floor` is a value at or below w_m(q) from which the
// recurrence still climbs (w_m(q-1) + C_m: the recurrence of q is that of q-1 plus C_m, and both
// are monotonic), so starting there skips iterations without changing the fixed point reached.
std::optional<std::int64_t> queuing_delay(const StreamContext& ctx, const CanBusTiming& timing, std::int64_t q,
                                          std::int64_t floor) {
  const std::int64_t own = ctx.self.transmission.count();
  const std::int64_t start = ctx.blocking + q * own;
  std::int64_t w = std::max(start, floor);
  if (w != start && w > kHorizonNs) return std::nullopt;  // the plain iteration would pass the horizon
  while (true) {
    const std::int64_t next = ctx.blocking + q * own + error_overhead(w + own, timing, ctx.largest_hep_frame) +
                              interference(ctx, w, timing.bit_time.count());
    if (next == w) return w;
    if (next > kHorizonNs) return std::nullopt;
    w = next;
  }
}

std::optional<Nanos> response_time(const StreamContext& ctx, const CanBusTiming& timing) {
  const auto t = busy_period(ctx, timing);
  if (!t) return std::nullopt;
  const std::int64_t period = ctx.self.period.count();
  const std::int64_t instances = std::max<std::int64_t>(1, ceil_div(*t + ctx.self.jitter.count(), period));
  std::int64_t worst = 0;
  std::int64_t floor = 0;
  for (std::int64_t q = 0; q < instances; ++q) {
    const auto w = queuing_delay(ctx, timing, q, floor);
    if (!w) return std::nullopt;
    floor = *w + ctx.self.transmission.count();
    worst = std::max(worst, ctx.self.jitter.count() + *w - q * period + ctx.self.transmission.count());
  }
  return Nanos(worst);
}

double share(const CanStream& s) {
  return static_cast<double>(s.transmission.count()) / static_cast<double>(s.period.count());
}

double fault_share(const CanBusTiming& timing, std::int64_t largest_hep_frame) {
  if (timing.errors.max_per_window == 0 || timing.errors.window.count() <= 0) return 0.0;
  return static_cast<double>(timing.errors.max_per_window) *
         static_cast<double>(timing.error_frame_time.count() + largest_hep_frame) /
         static_cast<double>(timing.errors.window.count());
}

// Sum of integer fractions kept exact: p / q with __int128, reduced at every step.
class ExactShare {
 public:
  // False once the sum can no longer be kept exact (its denominator grew past kLimit).
  bool add(std::int64_t numerator, std::int64_t denominator) {
    if (!exact_ || numerator == 0) return exact_;
    const __int128 g = gcd(q_, denominator);
    const __int128 scale = denominator / g;
    if (q_ > kLimit / scale) return exact_ = false;
    p_ = p_ * scale + numerator * (q_ / g);
    q_ *= scale;
    const __int128 r = gcd(p_, q_);
    p_ /= r;
    q_ /= r;
    return exact_;
  }
  bool at_least_one() const { return p_ >= q_; }

 private:
  static __int128 gcd(__int128 a, __int128 b) {
    while (b != 0) a = std::exchange(b, a % b);
    return a < 0 ? -a : a;
  }
  static constexpr __int128 kLimit = static_cast<__int128>(1) << 80;  // p stays far below 2^127
  __int128 p_ = 0;
  __int128 q_ = 1;
  bool exact_ = true;
};

// Whether level m's load (own stream, hp(m), fault share) is at least 100 %, decided exactly in
// integers: used only when the floating-point sum is within rounding of 100 %, where the order of
// the additions would otherwise decide. A sum too large to keep exact counts as full (unbounded).
bool level_full_exactly(std::span<const CanStream> streams, std::size_t index, const CanBusTiming& timing,
                        std::int64_t largest_hep_frame) {
  ExactShare load;
  bool exact = load.add(streams[index].transmission.count(), streams[index].period.count());
  for (std::size_t k = 0; k < streams.size(); ++k) {
    if (k != index && streams[k].can_id < streams[index].can_id)
      exact = load.add(streams[k].transmission.count(), streams[k].period.count());
  }
  if (timing.errors.max_per_window > 0 && timing.errors.window.count() > 0) {
    exact = load.add(
        static_cast<std::int64_t>(timing.errors.max_per_window) * (timing.error_frame_time.count() + largest_hep_frame),
        timing.errors.window.count());
  }
  return !exact || load.at_least_one();
}

constexpr double kRoundingMargin = 1e-9;

}  // namespace

std::uint32_t classic_frame_bits(std::uint32_t payload, CanIdFormat format) {
  const std::uint32_t g = format == CanIdFormat::extended29 ? 54 : 34;
  const std::uint32_t body = g + 8 * payload;
  return body + 13 + (body - 1) / 4;
}

namespace {
// The data lengths of CAN FD frames above 8 bytes: DLC codes 9..15.
constexpr std::array<std::uint32_t, 7> kFdLengths{12, 16, 20, 24, 32, 48, 64};
}  // namespace

std::uint32_t fd_padded_length(std::uint32_t payload) {
  if (payload <= kClassicMaxPayload) return payload;
  for (const std::uint32_t size : kFdLengths) {
    if (payload <= size) return size;
  }
  return kFdMaxPayload;
}

bool is_frame_length(std::uint32_t length, bool fd) {
  return length <= kClassicMaxPayload || (fd && length <= kFdMaxPayload && fd_padded_length(length) == length);
}

std::uint32_t dlc_length(std::uint32_t dlc) {
  return dlc <= kClassicMaxPayload ? dlc : kFdLengths[std::min<std::size_t>(dlc - 9, kFdLengths.size() - 1)];
}

FdFrameBits fd_frame_bits(std::uint32_t payload, CanIdFormat format) {
  const std::uint32_t length = fd_padded_length(payload);
  const std::uint32_t arbitration =
      format == CanIdFormat::extended29 ? kFdArbitrationBitsExtended : kFdArbitrationBitsStandard;
  const std::uint32_t crc = length > 16 ? 21 : 17;
  const std::uint32_t stuffed_data = 5 + 8 * length;  // ESI, DLC, data
  FdFrameBits bits;
  bits.nominal_bits = arbitration + (arbitration - 1) / 4 + kFdTrailerBits;
  // stuff count (4) + CRC, one fixed stuff bit per 4 bits of that field, then the CRC delimiter.
  bits.data_bits = stuffed_data + (stuffed_data - 1) / 4 + 4 + crc + (4 + crc + 3) / 4 + 1;
  return bits;
}

Nanos bit_time(BitRate rate) { return Nanos(ceil_div(1'000'000'000, static_cast<std::int64_t>(rate.bits_per_second))); }

namespace {
std::int64_t bits_to_ns(std::uint64_t bits, BitRate rate) {
  return ceil_div(static_cast<std::int64_t>(bits) * 1'000'000'000, static_cast<std::int64_t>(rate.bits_per_second));
}
}  // namespace

Nanos frame_time(const CanSegmentProperties& bus, std::uint32_t payload, CanIdFormat format) {
  if (!bus.fd) return Nanos(bits_to_ns(classic_frame_bits(payload, format), bus.bitrate));
  const FdFrameBits bits = fd_frame_bits(payload, format);
  const BitRate data_rate = bus.data_bitrate.bits_per_second > 0 ? bus.data_bitrate : bus.bitrate;
  return Nanos(bits_to_ns(bits.nominal_bits, bus.bitrate) + bits_to_ns(bits.data_bits, data_rate));
}

std::uint32_t max_frame_payload(const CanSegmentProperties& bus) { return bus.fd ? kFdMaxPayload : kClassicMaxPayload; }

CanBusTiming bus_timing(const CanSegmentProperties& bus) {
  return CanBusTiming{bit_time(bus.bitrate), Nanos(bits_to_ns(kErrorFrameBits, bus.bitrate)), bus.errors};
}

std::vector<std::optional<Nanos>> response_times(std::span<const CanStream> streams, const CanBusTiming& timing) {
  return CanBusAnalysis(streams, timing).results();
}

bool CanBusAnalysis::Entry::same_stream(const Entry& other) const {
  return transmission == other.transmission && period == other.period && jitter == other.jitter && tied == other.tied;
}

CanBusAnalysis::CanBusAnalysis(std::span<const CanStream> streams, const CanBusTiming& timing,
                               const CanBusAnalysis* previous)
    : timing_(timing), results_(streams.size()) {
  const std::size_t n = streams.size();
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return streams[a].can_id < streams[b].can_id; });
  entries_.resize(n);
  std::vector<Release> releases(n);
  for (std::size_t p = 0; p < n; ++p) {
    const CanStream& s = streams[order[p]];
    entries_[p].transmission = s.transmission.count();
    entries_[p].period = s.period.count();
    entries_[p].jitter = s.jitter.count();
    entries_[p].tied = p > 0 && streams[order[p - 1]].can_id == s.can_id;
    releases[p] =
        Release{s.period.count() - s.jitter.count(), p, s.transmission.count(), s.period.count(), s.jitter.count()};
  }
  std::sort(releases.begin(), releases.end(),
            [](const Release& a, const Release& b) { return a.threshold < b.threshold; });
  // Longest frame from position p to the end: the blocking of the level before p.
  std::vector<std::int64_t> longest_from(n + 1, 0);
  for (std::size_t p = n; p-- > 0;) longest_from[p] = std::max(longest_from[p + 1], entries_[p].transmission);

  const bool reusable = previous && previous->timing_ == timing;
  std::size_t same_prefix = 0;
  if (reusable) {
    const auto& old = previous->entries_;
    while (same_prefix < n && same_prefix < old.size() && entries_[same_prefix].same_stream(old[same_prefix]))
      ++same_prefix;
  }
  std::size_t first_of_level = 0;
  std::int64_t higher_frames = 0;
  std::int64_t longest_higher = 0;
  double higher_load = 0.0;
  for (std::size_t p = 0; p < n;) {
    std::size_t end = p + 1;
    while (end < n && entries_[end].tied) ++end;
    first_of_level = p;
    for (std::size_t m = p; m < end; ++m) {
      Entry& e = entries_[m];
      const std::size_t input = order[m];
      std::int64_t blocking = longest_from[end];
      for (std::size_t o = p; o < end; ++o) {
        if (o != m) blocking = std::max(blocking, entries_[o].transmission);
      }
      e.blocking = blocking;
      if (reusable && m < same_prefix && previous->entries_[m].blocking == blocking &&
          !previous->entries_[m].near_full) {
        e.result = previous->entries_[m].result;
      } else {
        StreamContext ctx{streams[input], first_of_level, blocking, std::max(longest_higher, e.transmission),
                          higher_frames,  &releases};
        double load = higher_load + share(streams[input]) + fault_share(timing, ctx.largest_hep_frame);
        e.near_full = std::abs(load - 1.0) < kRoundingMargin;
        const bool full = e.near_full ? level_full_exactly(streams, input, timing, ctx.largest_hep_frame) : load >= 1.0;
        e.result = full ? std::nullopt : response_time(ctx, timing);
        ++analysed_;
      }
      results_[input] = e.result;
    }
    for (std::size_t m = p; m < end; ++m) {
      higher_frames += entries_[m].transmission;
      longest_higher = std::max(longest_higher, entries_[m].transmission);
      higher_load += share(streams[order[m]]);
    }
    p = end;
  }
}

double utilization(std::span<const CanStream> streams) {
  double sum = 0.0;
  for (const CanStream& s : streams) {
    sum += static_cast<double>(s.transmission.count()) / static_cast<double>(s.period.count());
  }
  return sum;
}

}  // namespace cosmic

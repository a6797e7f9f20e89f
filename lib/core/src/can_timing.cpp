#include "cosmic/can_timing.hpp"

#include <algorithm>
#include <array>

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

std::int64_t ceil_div(std::int64_t numerator, std::int64_t denominator) {
  return numerator <= 0 ? 0 : (numerator + denominator - 1) / denominator;
}

std::int64_t error_overhead(std::int64_t interval, const CanBusTiming& timing, std::int64_t largest_hep_frame) {
  if (timing.errors.max_per_window == 0 || timing.errors.window.count() <= 0) return 0;
  const std::int64_t windows = ceil_div(interval, timing.errors.window.count());
  return windows * timing.errors.max_per_window * (timing.error_frame_time.count() + largest_hep_frame);
}

struct StreamContext {
  const CanStream& self;
  std::vector<const CanStream*> higher;  // hp(m)
  std::int64_t blocking = 0;             // B: longest lower-priority frame
  std::int64_t largest_hep_frame = 0;
};

StreamContext context_of(std::span<const CanStream> streams, std::size_t index) {
  StreamContext ctx{streams[index], {}, 0, streams[index].transmission.count()};
  for (std::size_t k = 0; k < streams.size(); ++k) {
    if (k == index) continue;
    const CanStream& other = streams[k];
    if (other.can_id < ctx.self.can_id) {
      ctx.higher.push_back(&other);
      ctx.largest_hep_frame = std::max(ctx.largest_hep_frame, other.transmission.count());
    } else {
      ctx.blocking = std::max(ctx.blocking, other.transmission.count());
    }
  }
  return ctx;
}

// Length of the priority level-m busy period; nullopt when it does not end within the horizon.
std::optional<std::int64_t> busy_period(const StreamContext& ctx, const CanBusTiming& timing) {
  std::int64_t t = ctx.self.transmission.count();
  while (true) {
    std::int64_t next = ctx.blocking + error_overhead(t, timing, ctx.largest_hep_frame) +
                        ceil_div(t + ctx.self.jitter.count(), ctx.self.period.count()) * ctx.self.transmission.count();
    for (const CanStream* k : ctx.higher) {
      next += ceil_div(t + k->jitter.count(), k->period.count()) * k->transmission.count();
    }
    if (next == t) return t;
    if (next > kHorizonNs) return std::nullopt;
    t = next;
  }
}

// Queuing delay w_m(q) of instance q.
std::optional<std::int64_t> queuing_delay(const StreamContext& ctx, const CanBusTiming& timing, std::int64_t q) {
  const std::int64_t own = ctx.self.transmission.count();
  std::int64_t w = ctx.blocking + q * own;
  while (true) {
    std::int64_t next = ctx.blocking + q * own + error_overhead(w + own, timing, ctx.largest_hep_frame);
    for (const CanStream* k : ctx.higher) {
      next += ceil_div(w + k->jitter.count() + timing.bit_time.count(), k->period.count()) * k->transmission.count();
    }
    if (next == w) return w;
    if (next > kHorizonNs) return std::nullopt;
    w = next;
  }
}

// Load of the streams at priority m or higher plus the worst error rate: at 1 or above the busy
// period never ends, which the recurrences would only find out at the horizon.
double level_load(const StreamContext& ctx, const CanBusTiming& timing) {
  double load = static_cast<double>(ctx.self.transmission.count()) / static_cast<double>(ctx.self.period.count());
  for (const CanStream* k : ctx.higher) {
    load += static_cast<double>(k->transmission.count()) / static_cast<double>(k->period.count());
  }
  if (timing.errors.max_per_window > 0 && timing.errors.window.count() > 0) {
    load += static_cast<double>(timing.errors.max_per_window) *
            static_cast<double>(timing.error_frame_time.count() + ctx.largest_hep_frame) /
            static_cast<double>(timing.errors.window.count());
  }
  return load;
}

std::optional<Nanos> response_time(const StreamContext& ctx, const CanBusTiming& timing) {
  if (level_load(ctx, timing) >= 1.0) return std::nullopt;
  const auto t = busy_period(ctx, timing);
  if (!t) return std::nullopt;
  const std::int64_t period = ctx.self.period.count();
  const std::int64_t instances = std::max<std::int64_t>(1, ceil_div(*t + ctx.self.jitter.count(), period));
  std::int64_t worst = 0;
  for (std::int64_t q = 0; q < instances; ++q) {
    const auto w = queuing_delay(ctx, timing, q);
    if (!w) return std::nullopt;
    worst = std::max(worst, ctx.self.jitter.count() + *w - q * period + ctx.self.transmission.count());
  }
  return Nanos(worst);
}

}  // namespace

std::uint32_t classic_frame_bits(std::uint32_t payload, CanIdFormat format) {
  const std::uint32_t g = format == CanIdFormat::extended29 ? 54 : 34;
  const std::uint32_t body = g + 8 * payload;
  return body + 13 + (body - 1) / 4;
}

std::uint32_t fd_padded_length(std::uint32_t payload) {
  if (payload <= 8) return payload;
  constexpr std::array<std::uint32_t, 7> kSizes{12, 16, 20, 24, 32, 48, 64};
  for (const std::uint32_t size : kSizes) {
    if (payload <= size) return size;
  }
  return 64;
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

Nanos bit_time(BitRate rate) {
  return Nanos(ceil_div(1'000'000'000, static_cast<std::int64_t>(rate.bits_per_second)));
}

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

std::uint32_t max_frame_payload(const CanSegmentProperties& bus) {
  return bus.fd ? kFdMaxPayload : kClassicMaxPayload;
}

CanBusTiming bus_timing(const CanSegmentProperties& bus) {
  return CanBusTiming{bit_time(bus.bitrate), Nanos(bits_to_ns(kErrorFrameBits, bus.bitrate)), bus.errors};
}

std::vector<std::optional<Nanos>> response_times(std::span<const CanStream> streams, const CanBusTiming& timing) {
  std::vector<std::optional<Nanos>> out;
  out.reserve(streams.size());
  for (std::size_t i = 0; i < streams.size(); ++i) {
    out.push_back(response_time(context_of(streams, i), timing));
  }
  return out;
}

double utilization(std::span<const CanStream> streams) {
  double sum = 0.0;
  for (const CanStream& s : streams) {
    sum += static_cast<double>(s.transmission.count()) / static_cast<double>(s.period.count());
  }
  return sum;
}

}  // namespace cosmic

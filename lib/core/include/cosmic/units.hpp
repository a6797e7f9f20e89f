// Physical quantities used across the gateway and their textual form ("10ms", "500kbit/s").
// Pure value types; parsing never throws.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cosmic {

using Nanos = std::chrono::nanoseconds;

// Bits per second.
struct BitRate {
  std::uint64_t bits_per_second = 0;
  friend auto operator<=>(const BitRate&, const BitRate&) = default;
};

// Outcome of parsing one quantity: the value, or why the text is not one.
template <typename T>
struct Parsed {
  std::optional<T> value;
  std::string error;  // empty when value is set
};

// "250us", "10ms", "1.5s", "100ns". Must be >= 0 and a whole number of nanoseconds.
Parsed<Nanos> parse_duration(std::string_view text);
// "500kbit/s", "1Mbit/s", "2000000bit/s".
Parsed<BitRate> parse_bitrate(std::string_view text);
// "8B", "1KiB", "64B". Bytes.
Parsed<std::uint64_t> parse_size(std::string_view text);
// "70%" -> 0.70. Range 0..100 %.
Parsed<double> parse_percent(std::string_view text);
// "100Hz", "2.5kHz". Events per second, from 1e-9 (one per 1e9 s, the longest duration) to 1e9.
// Numbers have at most 30 digits; every refusal quotes the text cut to a readable length.
Parsed<double> parse_frequency(std::string_view text);
// Minimum inter-arrival time of `hz` events per second, rounded down (a conservative, higher
// load); `hz` is clamped to parse_frequency's range, so the result is 1 ns to 1e9 s.
Nanos period_of_rate(double hz);
// A value quoted in an error message: 'text', cut after 24 characters with its full length.
std::string quote_value(std::string_view text);

// Human-readable forms used in reports: "3.2 ms", "500 kbit/s".
std::string format_duration(Nanos value);
std::string format_seconds(double seconds);
std::string format_bitrate(BitRate value);
// 0.7 -> "70.0%"
std::string format_percent(double ratio);

double to_seconds(Nanos value);

}  // namespace cosmic

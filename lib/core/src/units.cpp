#include "cosmic/units.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace cosmic {
namespace {

struct UnitFactor {
  std::string_view suffix;
  long double factor;  // base units per one of this unit
};

struct SplitQuantity {
  long double number = 0;
  std::string_view suffix;
  bool ok = false;
};

// More digits than any quantity here needs: beyond this a number is an attack or a typo.
constexpr std::size_t kMaxDigits = 30;

std::string_view trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  return text;
}

// Splits "12.5 ms" into 12.5 and "ms". Accepts digits with one optional decimal point.
SplitQuantity split_quantity(std::string_view text) {
  text = trim(text);
  std::size_t end = 0;
  bool seen_digit = false;
  bool seen_point = false;
  while (end < text.size()) {
    const char c = text[end];
    if (c >= '0' && c <= '9') {
      seen_digit = true;
    } else if (c == '.' && !seen_point) {
      seen_point = true;
    } else {
      break;
    }
    ++end;
  }
  SplitQuantity out;
  if (!seen_digit || end > kMaxDigits) return out;
  const std::string number_text(text.substr(0, end));
  out.number = std::strtold(number_text.c_str(), nullptr);
  out.suffix = trim(text.substr(end));
  out.ok = true;
  return out;
}

std::size_t digit_count(std::string_view text) {
  text = trim(text);
  std::size_t digits = 0;
  while (digits < text.size() && ((text[digits] >= '0' && text[digits] <= '9') || text[digits] == '.')) ++digits;
  return digits;
}

template <std::size_t N>
std::optional<long double> scale(const SplitQuantity& q, const std::array<UnitFactor, N>& units) {
  for (const auto& unit : units) {
    if (q.suffix == unit.suffix) return q.number * unit.factor;
  }
  return std::nullopt;
}

template <typename T, std::size_t N>
Parsed<long double> parse_with_units(std::string_view text, const std::array<UnitFactor, N>& units,
                                     std::string_view expected) {
  const SplitQuantity q = split_quantity(text);
  if (!q.ok && digit_count(text) > kMaxDigits) {
    return {std::nullopt, quote_value(text) + " has " + std::to_string(digit_count(text)) + " digits (at most " +
                              std::to_string(kMaxDigits) + ", " + std::string(expected) + ")"};
  }
  if (!q.ok) return {std::nullopt, quote_value(text) + " is not a number with a unit (" + std::string(expected) + ")"};
  if (q.suffix.empty()) return {std::nullopt, quote_value(text) + " has no unit (" + std::string(expected) + ")"};
  const auto value = scale(q, units);
  if (!value) {
    return {std::nullopt, "unknown unit '" + std::string(q.suffix.substr(0, 16)) + "' in " + quote_value(text) + " (" +
                              std::string(expected) + ")"};
  }
  return {value, {}};
}

constexpr std::array<UnitFactor, 5> kDurationUnits{
    {{"ns", 1.0L}, {"us", 1e3L}, {"ms", 1e6L}, {"s", 1e9L}, {"min", 60e9L}}};
constexpr std::array<UnitFactor, 4> kBitrateUnits{
    {{"bit/s", 1.0L}, {"kbit/s", 1e3L}, {"Mbit/s", 1e6L}, {"Gbit/s", 1e9L}}};
constexpr std::array<UnitFactor, 3> kSizeUnits{{{"B", 1.0L}, {"KiB", 1024.0L}, {"MiB", 1048576.0L}}};
constexpr std::array<UnitFactor, 1> kPercentUnits{{{"%", 0.01L}}};
constexpr std::array<UnitFactor, 3> kFrequencyUnits{{{"Hz", 1.0L}, {"kHz", 1e3L}, {"MHz", 1e6L}}};

bool is_whole(long double value) { return std::fabs(value - std::round(value)) < 1e-6L; }

}  // namespace

Parsed<Nanos> parse_duration(std::string_view text) {
  const auto raw = parse_with_units<Nanos>(text, kDurationUnits, "a duration such as 250us, 10ms, 1.5s");
  if (!raw.value) return {std::nullopt, raw.error};
  if (!is_whole(*raw.value)) return {std::nullopt, quote_value(text) + " is not a whole number of nanoseconds"};
  if (*raw.value > 1e18L) return {std::nullopt, quote_value(text) + " is too long (at most 1e9 s)"};
  return {Nanos(static_cast<std::int64_t>(std::llround(*raw.value))), {}};
}

Parsed<BitRate> parse_bitrate(std::string_view text) {
  const auto raw = parse_with_units<BitRate>(text, kBitrateUnits, "a bit rate such as 500kbit/s or 1Mbit/s");
  if (!raw.value) return {std::nullopt, raw.error};
  if (!is_whole(*raw.value)) return {std::nullopt, quote_value(text) + " is not a whole number of bit/s"};
  if (*raw.value < 1.0L || *raw.value > 1e12L)
    return {std::nullopt, quote_value(text) + " is out of range (1bit/s to 1000Gbit/s)"};
  return {BitRate{static_cast<std::uint64_t>(std::llround(*raw.value))}, {}};
}

Parsed<std::uint64_t> parse_size(std::string_view text) {
  const auto raw = parse_with_units<std::uint64_t>(text, kSizeUnits, "a size such as 8B, 64B or 1KiB");
  if (!raw.value) return {std::nullopt, raw.error};
  if (!is_whole(*raw.value)) return {std::nullopt, quote_value(text) + " is not a whole number of bytes"};
  if (*raw.value > 1e12L) return {std::nullopt, quote_value(text) + " is too large"};
  return {static_cast<std::uint64_t>(std::llround(*raw.value)), {}};
}

Parsed<double> parse_percent(std::string_view text) {
  const auto raw = parse_with_units<double>(text, kPercentUnits, "a percentage such as 70%");
  if (!raw.value) return {std::nullopt, raw.error};
  if (*raw.value < 0.0L || *raw.value > 1.0L)
    return {std::nullopt, quote_value(text) + " is out of range (0% to 100%)"};
  return {static_cast<double>(*raw.value), {}};
}

Parsed<double> parse_frequency(std::string_view text) {
  const auto raw = parse_with_units<double>(text, kFrequencyUnits, "a rate such as 100Hz or 2kHz");
  if (!raw.value) return {std::nullopt, raw.error};
  // The floor keeps the period (1 / rate) within the longest duration, 1e9 s.
  if (*raw.value < 1e-9L || *raw.value > 1e9L) {
    return {std::nullopt, quote_value(text) + " is out of range (from 0.000000001Hz, one event per 1e9 s, to 1000MHz)"};
  }
  return {static_cast<double>(*raw.value), {}};
}

Nanos period_of_rate(double hz) {
  const long double nanos = std::floor(1e9L / std::clamp(static_cast<long double>(hz), 1e-9L, 1e9L));
  return Nanos(std::max<std::int64_t>(1, static_cast<std::int64_t>(nanos)));
}

std::string quote_value(std::string_view text) {
  constexpr std::size_t kShown = 24;
  if (text.size() <= kShown) return "'" + std::string(text) + "'";
  return "'" + std::string(text.substr(0, kShown)) + "...' (" + std::to_string(text.size()) + " characters)";
}

double to_seconds(Nanos value) { return static_cast<double>(value.count()) * 1e-9; }

std::string format_seconds(double seconds) {
  char buffer[64];
  const double magnitude = std::fabs(seconds);
  if (std::isinf(seconds)) return "unbounded";
  if (magnitude >= 1.0) {
    std::snprintf(buffer, sizeof buffer, "%.3g s", seconds);
  } else if (magnitude >= 1e-3) {
    std::snprintf(buffer, sizeof buffer, "%.3g ms", seconds * 1e3);
  } else if (magnitude >= 1e-6 || magnitude == 0.0) {
    std::snprintf(buffer, sizeof buffer, "%.3g us", seconds * 1e6);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.3g ns", seconds * 1e9);
  }
  return buffer;
}

std::string format_duration(Nanos value) { return format_seconds(to_seconds(value)); }

std::string format_percent(double ratio) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f%%", ratio * 100.0);
  return buffer;
}

std::string format_bitrate(BitRate value) {
  char buffer[64];
  const double bps = static_cast<double>(value.bits_per_second);
  if (bps >= 1e9) {
    std::snprintf(buffer, sizeof buffer, "%g Gbit/s", bps / 1e9);
  } else if (bps >= 1e6) {
    std::snprintf(buffer, sizeof buffer, "%g Mbit/s", bps / 1e6);
  } else if (bps >= 1e3) {
    std::snprintf(buffer, sizeof buffer, "%g kbit/s", bps / 1e3);
  } else {
    std::snprintf(buffer, sizeof buffer, "%g bit/s", bps);
  }
  return buffer;
}

}  // namespace cosmic

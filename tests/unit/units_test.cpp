// Quantities with units: every unit kind, the whole-number rules and the error messages.
#include "cosmic/units.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace cosmic {
namespace {

template <typename T>
void expect_error(const Parsed<T>& parsed, const std::string& fragment) {
  EXPECT_FALSE(parsed.value.has_value());
  EXPECT_NE(parsed.error.find(fragment), std::string::npos) << "error was: " << parsed.error;
}

TEST(Units, DurationEveryUnit) {
  EXPECT_EQ(parse_duration("100ns").value, Nanos(100));
  EXPECT_EQ(parse_duration("250us").value, Nanos(250'000));
  EXPECT_EQ(parse_duration("10ms").value, Nanos(10'000'000));
  EXPECT_EQ(parse_duration("1.5s").value, Nanos(1'500'000'000));
  EXPECT_EQ(parse_duration("2min").value, Nanos(120'000'000'000));
  EXPECT_EQ(parse_duration("0.1ms").value, Nanos(100'000));  // 0.1 is inexact in binary: rounded
  EXPECT_EQ(parse_duration(".5ms").value, Nanos(500'000));
  EXPECT_EQ(parse_duration(" 10 ms ").value, Nanos(10'000'000));  // blanks around and between
  EXPECT_EQ(parse_duration("0ms").value, Nanos(0));               // >= 0 allowed here
  EXPECT_TRUE(parse_duration("10ms").error.empty());
}

TEST(Units, DurationWholeNanoseconds) {
  expect_error(parse_duration("1.5ns"), "is not a whole number of nanoseconds");
  expect_error(parse_duration("0.0005us"), "is not a whole number of nanoseconds");  // 0.5 ns
  EXPECT_EQ(parse_duration("0.001us").value, Nanos(1));
}

TEST(Units, DurationErrors) {
  expect_error(parse_duration(""), "'' is not a number with a unit");
  expect_error(parse_duration("-5ms"), "'-5ms' is not a number with a unit");
  expect_error(parse_duration("ms"), "is not a number with a unit");
  expect_error(parse_duration("10"), "'10' has no unit");
  expect_error(parse_duration("10 sec"), "unknown unit 'sec' in '10 sec'");
  expect_error(parse_duration("10MS"), "unknown unit 'MS'");  // units are case-sensitive
  expect_error(parse_duration("1e3ms"), "unknown unit 'e3ms'");
  expect_error(parse_duration("2000000000s"), "too long");
  // Every message says what would be valid.
  EXPECT_NE(parse_duration("10").error.find("250us, 10ms, 1.5s"), std::string::npos);
}

TEST(Units, BitRateEveryUnit) {
  EXPECT_EQ(parse_bitrate("2000000bit/s").value, BitRate{2'000'000});
  EXPECT_EQ(parse_bitrate("500kbit/s").value, BitRate{500'000});
  EXPECT_EQ(parse_bitrate("125kbit/s").value, BitRate{125'000});
  EXPECT_EQ(parse_bitrate("1Mbit/s").value, BitRate{1'000'000});
  EXPECT_EQ(parse_bitrate("1.5Mbit/s").value, BitRate{1'500'000});
  EXPECT_EQ(parse_bitrate("1Gbit/s").value, BitRate{1'000'000'000});
}

TEST(Units, BitRateErrors) {
  expect_error(parse_bitrate("0.5bit/s"), "is not a whole number of bit/s");
  expect_error(parse_bitrate("0bit/s"), "out of range");
  expect_error(parse_bitrate("2000Gbit/s"), "out of range");
  expect_error(parse_bitrate("500kbps"), "unknown unit 'kbps'");
  expect_error(parse_bitrate("500k"), "unknown unit 'k'");
  expect_error(parse_bitrate("500000"), "has no unit");
  expect_error(parse_bitrate("-1Mbit/s"), "is not a number with a unit");
  expect_error(parse_bitrate(""), "is not a number with a unit");
}

TEST(Units, SizeEveryUnit) {
  EXPECT_EQ(parse_size("8B").value, 8u);
  EXPECT_EQ(parse_size("64B").value, 64u);
  EXPECT_EQ(parse_size("0B").value, 0u);
  EXPECT_EQ(parse_size("1KiB").value, 1024u);
  EXPECT_EQ(parse_size("0.5KiB").value, 512u);
  EXPECT_EQ(parse_size("2MiB").value, 2u * 1048576u);
}

TEST(Units, SizeErrors) {
  expect_error(parse_size("1.5B"), "is not a whole number of bytes");
  expect_error(parse_size("0.1KiB"), "is not a whole number of bytes");  // 102.4 B
  expect_error(parse_size("8"), "'8' has no unit");
  expect_error(parse_size("8 bytes"), "unknown unit 'bytes'");
  expect_error(parse_size("1KB"), "unknown unit 'KB'");  // KiB, not KB
  expect_error(parse_size("-8B"), "is not a number with a unit");
  expect_error(parse_size(""), "is not a number with a unit");
}

TEST(Units, PercentEveryValue) {
  EXPECT_DOUBLE_EQ(*parse_percent("70%").value, 0.70);
  EXPECT_DOUBLE_EQ(*parse_percent("0%").value, 0.0);
  EXPECT_DOUBLE_EQ(*parse_percent("100%").value, 1.0);
  EXPECT_DOUBLE_EQ(*parse_percent("12.5%").value, 0.125);
}

TEST(Units, PercentErrors) {
  expect_error(parse_percent("101%"), "'101%' is out of range (0% to 100%)");
  expect_error(parse_percent("70"), "has no unit");
  expect_error(parse_percent("0.7"), "has no unit");
  expect_error(parse_percent("-5%"), "is not a number with a unit");
  expect_error(parse_percent("70 percent"), "unknown unit 'percent'");
}

TEST(Units, FrequencyEveryUnit) {
  EXPECT_DOUBLE_EQ(*parse_frequency("100Hz").value, 100.0);
  EXPECT_DOUBLE_EQ(*parse_frequency("2.5kHz").value, 2500.0);
  EXPECT_DOUBLE_EQ(*parse_frequency("1MHz").value, 1e6);
  EXPECT_DOUBLE_EQ(*parse_frequency("0.5Hz").value, 0.5);  // fractional rates are fine
}

TEST(Units, FrequencyErrors) {
  expect_error(parse_frequency("0Hz"), "out of range");  // a rate must be above zero
  expect_error(parse_frequency("2000MHz"), "out of range");
  expect_error(parse_frequency("100hz"), "unknown unit 'hz'");
  expect_error(parse_frequency("100"), "has no unit");
  expect_error(parse_frequency("-1Hz"), "is not a number with a unit");
}

TEST(Units, Formatting) {
  EXPECT_EQ(format_duration(Nanos(3'200'000)), "3.2 ms");
  EXPECT_EQ(format_duration(Nanos(3'500'000)), "3.5 ms");
  EXPECT_EQ(format_duration(Nanos(250'000)), "250 us");
  EXPECT_EQ(format_duration(Nanos(0)), "0 us");
  EXPECT_EQ(format_duration(Nanos(40)), "40 ns");
  EXPECT_EQ(format_seconds(1.5), "1.5 s");
  EXPECT_EQ(format_seconds(0.005), "5 ms");
  EXPECT_EQ(format_seconds(std::numeric_limits<double>::infinity()), "unbounded");
  EXPECT_EQ(format_bitrate(BitRate{500'000}), "500 kbit/s");
  EXPECT_EQ(format_bitrate(BitRate{1'000'000}), "1 Mbit/s");
  EXPECT_EQ(format_bitrate(BitRate{2'000'000'000}), "2 Gbit/s");
  EXPECT_EQ(format_bitrate(BitRate{100}), "100 bit/s");
  EXPECT_DOUBLE_EQ(to_seconds(Nanos(1'500'000)), 0.0015);
}

}  // namespace
}  // namespace cosmic

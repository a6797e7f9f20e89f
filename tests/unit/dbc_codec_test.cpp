// The DBC codec (cosmic/dbc_codec.hpp): Intel and Motorola layouts against bytes worked out by hand
// from the DBC bit numbering, sign extension, scaling and rounding, IEEE float signals, range
// checks with saturation, and multiplexed signals present only when their switch selects them.
// (tests/integration/dbc checks the same codec against python3-canmatrix.)
#include "cosmic/dbc_codec.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstdint>
#include <limits>

namespace cosmic {
namespace {

DbcSignal layout(std::uint32_t start, std::uint32_t size, DbcByteOrder order, bool is_signed = false) {
  DbcSignal s;
  s.name = "S";
  s.start_bit = start;
  s.size = size;
  s.order = order;
  s.is_signed = is_signed;
  return s;
}

using Frame = std::array<std::uint8_t, 8>;

Frame written(const DbcSignal& s, std::uint64_t bits) {
  Frame frame{};
  dbc_write_bits(s, bits, frame);
  return frame;
}

constexpr auto intel = DbcByteOrder::little_endian;
constexpr auto motorola = DbcByteOrder::big_endian;

TEST(DbcCodec, IntelPutsTheLeastSignificantBitAtTheStartBit) {
  EXPECT_EQ(written(layout(0, 16, intel), 0x1234), (Frame{0x34, 0x12}));
  EXPECT_EQ(written(layout(4, 12, intel), 0xABC), (Frame{0xC0, 0xAB}));
  EXPECT_EQ(written(layout(0, 64, intel), 0x0102030405060708), (Frame{8, 7, 6, 5, 4, 3, 2, 1}));
  const Frame frame{0x34, 0x12};
  EXPECT_EQ(dbc_read_bits(layout(0, 16, intel), frame), 0x1234u);
}

TEST(DbcCodec, MotorolaPutsTheMostSignificantBitAtTheStartBitAndGoesOnInTheNextByte) {
  EXPECT_EQ(written(layout(7, 16, motorola), 0x1234), (Frame{0x12, 0x34}));
  // Start bit 11 is bit 3 of byte 1: the top four bits there, the low eight in byte 2.
  EXPECT_EQ(written(layout(11, 12, motorola), 0xABC), (Frame{0x00, 0x0A, 0xBC}));
  EXPECT_EQ(written(layout(7, 64, motorola), 0x0102030405060708), (Frame{1, 2, 3, 4, 5, 6, 7, 8}));
  const Frame frame{0x00, 0x0A, 0xBC};
  EXPECT_EQ(dbc_read_bits(layout(11, 12, motorola), frame), 0xABCu);
}

TEST(DbcCodec, WritingLeavesTheOtherBitsAlone) {
  Frame frame;
  frame.fill(0xFF);
  dbc_write_bits(layout(4, 8, intel), 0x00, frame);
  EXPECT_EQ(frame, (Frame{0x0F, 0xF0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
}

TEST(DbcCodec, FitsCountsEveryBitOfBothOrders) {
  EXPECT_TRUE(dbc_signal_fits(layout(56, 8, intel), 8));
  EXPECT_FALSE(dbc_signal_fits(layout(57, 8, intel), 8));
  EXPECT_TRUE(dbc_signal_fits(layout(11, 12, motorola), 3));
  EXPECT_FALSE(dbc_signal_fits(layout(11, 12, motorola), 2));
  EXPECT_TRUE(dbc_signal_fits(layout(0, 2, motorola), 2));  // bit 0, then bit 7 of byte 1 (15)
  EXPECT_FALSE(dbc_signal_fits(layout(0, 2, motorola), 1));
  EXPECT_FALSE(dbc_signal_fits(layout(56, 2, motorola), 8));  // bit 56 then bit 71: past the frame
  EXPECT_FALSE(dbc_signal_fits(layout(0, 0, intel), 8));
}

TEST(DbcCodec, SignedRawValuesAndScaling) {
  DbcSignal temp = layout(24, 8, intel, true);
  temp.factor = 0.5;
  temp.offset = -40;
  EXPECT_EQ(dbc_raw_integer(temp, 0xFF), -1);
  EXPECT_DOUBLE_EQ(dbc_physical(temp, 0xFF), -40.5);
  EXPECT_DOUBLE_EQ(dbc_physical(temp, 0x7F), 23.5);
  EXPECT_EQ(dbc_bits_for(temp, -40.5), 0xFFu);
  EXPECT_EQ(dbc_bits_for(temp, 23.5), 0x7Fu);
  EXPECT_EQ(dbc_bits_for(temp, 23.6), 0x7Fu);  // rounds to the nearest raw value
  EXPECT_EQ(dbc_raw_minimum(temp), -128);
  EXPECT_EQ(dbc_raw_maximum(temp), 127);
  DbcSignal volts = layout(8, 16, intel);
  volts.factor = 0.01;
  EXPECT_DOUBLE_EQ(dbc_physical(volts, 1234), 12.34);
  EXPECT_EQ(dbc_bits_for(volts, 12.34), 1234u);
}

TEST(DbcCodec, ValuesOutsideTheRawRangeAreRefusedOrSaturated) {
  DbcSignal temp = layout(0, 8, intel, true);
  temp.factor = 0.5;
  temp.offset = -40;
  EXPECT_FALSE(dbc_bits_for(temp, 24.0));    // raw 128
  EXPECT_FALSE(dbc_bits_for(temp, -104.5));  // raw -129
  EXPECT_FALSE(dbc_bits_for(temp, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(dbc_saturated_bits_for(temp, 1000.0), 0x7Fu);
  EXPECT_EQ(dbc_saturated_bits_for(temp, -1000.0), 0x80u);
  EXPECT_EQ(dbc_saturated_bits_for(temp, std::numeric_limits<double>::quiet_NaN()), 0u);
  const DbcSignal flag = layout(0, 1, intel);
  EXPECT_EQ(dbc_bits_for(flag, 1.0), 1u);
  EXPECT_FALSE(dbc_bits_for(flag, 2.0));
  EXPECT_FALSE(dbc_bits_for(flag, -1.0));
  EXPECT_EQ(dbc_saturated_bits_for(flag, 7.0), 1u);
  const DbcSignal wide = layout(0, 64, intel);
  EXPECT_EQ(dbc_bits_for(wide, 18446744073709549568.0), 0xFFFFFFFFFFFFF800u);  // the largest double below 2^64
  EXPECT_FALSE(dbc_bits_for(wide, 18446744073709551616.0));                    // 2^64
}

TEST(DbcCodec, IeeeFloatSignals) {
  DbcSignal pressure = layout(0, 32, intel, true);
  pressure.value_type = DbcValueType::float32;
  const auto bits = dbc_bits_for(pressure, 1.5);
  ASSERT_TRUE(bits);
  EXPECT_EQ(*bits, 0x3FC00000u);
  EXPECT_EQ(written(pressure, *bits), (Frame{0x00, 0x00, 0xC0, 0x3F}));
  EXPECT_DOUBLE_EQ(dbc_physical(pressure, 0x3FC00000u), 1.5);
  EXPECT_FALSE(dbc_bits_for(pressure, 1e39));  // beyond float
  DbcSignal energy = layout(7, 64, motorola, true);
  energy.value_type = DbcValueType::float64;
  energy.factor = 2.0;
  EXPECT_EQ(dbc_bits_for(energy, -3.0), std::bit_cast<std::uint64_t>(-1.5));
  EXPECT_DOUBLE_EQ(dbc_physical(energy, std::bit_cast<std::uint64_t>(-1.5)), -3.0);
}

TEST(DbcCodec, MultiplexedSignalsArePresentOnlyWhenTheirSwitchSelectsThem) {
  DbcMessage diag;
  DbcSignal mode = layout(0, 8, intel);
  mode.name = "Mode";
  mode.multiplex = DbcMultiplex::multiplexor;
  DbcSignal dtc = layout(8, 16, intel);
  dtc.name = "Dtc";
  dtc.multiplex = DbcMultiplex::multiplexed;
  dtc.multiplex_value = 0;
  DbcSignal freeze = layout(8, 32, intel);
  freeze.name = "Freeze";
  freeze.multiplex = DbcMultiplex::multiplexed;
  freeze.multiplex_value = 1;
  diag.signals = {mode, dtc, freeze};
  const Frame zero{0x00};
  const Frame one{0x01};
  EXPECT_EQ(dbc_multiplexor(diag), &diag.signals[0]);
  EXPECT_TRUE(dbc_signal_present(diag, diag.signals[0], zero));
  EXPECT_TRUE(dbc_signal_present(diag, diag.signals[1], zero));
  EXPECT_FALSE(dbc_signal_present(diag, diag.signals[2], zero));
  EXPECT_FALSE(dbc_signal_present(diag, diag.signals[1], one));
  EXPECT_TRUE(dbc_signal_present(diag, diag.signals[2], one));
}

TEST(DbcCodec, AShortBufferReadsZerosAndIsNotWrittenPast) {
  std::array<std::uint8_t, 2> small{0xFF, 0xFF};
  EXPECT_EQ(dbc_read_bits(layout(8, 16, intel), small), 0xFFu);
  dbc_write_bits(layout(8, 16, intel), 0x0000, small);
  EXPECT_EQ(small, (std::array<std::uint8_t, 2>{0xFF, 0x00}));
}

}  // namespace
}  // namespace cosmic

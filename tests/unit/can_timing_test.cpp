// CAN frame times (classic and FD, worst-case stuffing), the response-time analysis of Davis,
// Burns, Bril and Lukkien 2007 with the fault term, and the identifier layout of DESIGN.md §5.
#include "cosmic/can_timing.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>

#include <array>
#include <optional>
#include <vector>

#include "cosmic/can_wire.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

// ---------------------------------------------------------------- classic frames

// C = g + 8s + 13 + floor((g + 8s - 1) / 4) bits, g = 34 (11-bit id) or 54 (29-bit id).
TEST(ClassicFrame, BitsWorstCaseStuffing) {
  // 8 B extended: 54 + 64 = 118; 118 + 13 + floor(117/4) = 131 + 29 = 160.
  EXPECT_EQ(classic_frame_bits(8, CanIdFormat::extended29), 160u);
  // 8 B standard: 34 + 64 = 98; 98 + 13 + floor(97/4) = 111 + 24 = 135.
  EXPECT_EQ(classic_frame_bits(8, CanIdFormat::standard11), 135u);
  // 0 B standard: 34; 34 + 13 + floor(33/4) = 47 + 8 = 55.
  EXPECT_EQ(classic_frame_bits(0, CanIdFormat::standard11), 55u);
  // 0 B extended: 54; 54 + 13 + floor(53/4) = 67 + 13 = 80.
  EXPECT_EQ(classic_frame_bits(0, CanIdFormat::extended29), 80u);
  // 1 B extended: 62; 62 + 13 + floor(61/4) = 75 + 15 = 90.
  EXPECT_EQ(classic_frame_bits(1, CanIdFormat::extended29), 90u);
  // 4 B extended: 86; 86 + 13 + floor(85/4) = 99 + 21 = 120.
  EXPECT_EQ(classic_frame_bits(4, CanIdFormat::extended29), 120u);
}

TEST(ClassicFrame, BitTimeRoundsUp) {
  EXPECT_EQ(bit_time(BitRate{1'000'000}), Nanos(1'000));
  EXPECT_EQ(bit_time(BitRate{500'000}), Nanos(2'000));
  EXPECT_EQ(bit_time(BitRate{125'000}), Nanos(8'000));
  EXPECT_EQ(bit_time(BitRate{300'000}), Nanos(3'334));  // 3333.3 ns, rounded up: conservative
}

TEST(ClassicFrame, FrameTimeAt125kbit) {
  CanSegmentProperties bus;
  bus.bitrate = BitRate{125'000};  // 8 us per bit
  // 160 bits * 8 us = 1.28 ms; 135 bits * 8 us = 1.08 ms; 55 bits * 8 us = 440 us.
  EXPECT_EQ(frame_time(bus, 8, CanIdFormat::extended29), Nanos(1'280'000));
  EXPECT_EQ(frame_time(bus, 8, CanIdFormat::standard11), Nanos(1'080'000));
  EXPECT_EQ(frame_time(bus, 0, CanIdFormat::standard11), Nanos(440'000));
  EXPECT_EQ(max_frame_payload(bus), 8u);
}

TEST(ClassicFrame, FrameTimeAt1Mbit) {
  CanSegmentProperties bus;
  bus.bitrate = BitRate{1'000'000};
  // 160 bit-times at 1 us: 6,250 frames/s (DESIGN.md §9).
  EXPECT_EQ(frame_time(bus, 8, CanIdFormat::extended29), Nanos(160'000));
  // 0 B standard: 55 bits = 55 us: about 18,200 frames/s (DESIGN.md §9).
  EXPECT_EQ(frame_time(bus, 0, CanIdFormat::standard11), Nanos(55'000));
}

TEST(ClassicFrame, BusTiming) {
  CanSegmentProperties bus;
  bus.bitrate = BitRate{125'000};
  bus.errors = CanFaultHypothesis{2, Nanos(10ms)};
  const CanBusTiming timing = bus_timing(bus);
  EXPECT_EQ(timing.bit_time, Nanos(8'000));
  EXPECT_EQ(timing.error_frame_time, Nanos(31 * 8'000));  // kErrorFrameBits = 31
  EXPECT_EQ(timing.errors.max_per_window, 2u);
  EXPECT_EQ(timing.errors.window, Nanos(10ms));
}

// ---------------------------------------------------------------- CAN FD frames

TEST(FdFrame, PaddedLengths) {
  for (std::uint32_t n = 0; n <= 8; ++n) EXPECT_EQ(fd_padded_length(n), n);
  const std::array<std::pair<std::uint32_t, std::uint32_t>, 14> cases{{{9, 12},
                                                                       {12, 12},
                                                                       {13, 16},
                                                                       {16, 16},
                                                                       {17, 20},
                                                                       {20, 20},
                                                                       {21, 24},
                                                                       {24, 24},
                                                                       {25, 32},
                                                                       {32, 32},
                                                                       {33, 48},
                                                                       {48, 48},
                                                                       {49, 64},
                                                                       {64, 64}}};
  for (const auto& [payload, padded] : cases) EXPECT_EQ(fd_padded_length(payload), padded) << payload;
}

// Field by field, worst-case stuffing:
//  nominal rate: arbitration (extended: SOF 1 + base id 11 + SRR 1 + IDE 1 + id ext 18 + RRS 1 +
//    FDF 1 + res 1 + BRS 1 = 36; standard: SOF 1 + id 11 + RRS 1 + IDE 1 + FDF 1 + res 1 + BRS 1 =
//    17), dynamic stuff bits floor((n-1)/4), trailer ACK 1 + ACK del 1 + EOF 7 + IFS 3 = 12.
//  data rate: ESI 1 + DLC 4 + 8*len, dynamic stuff floor((n-1)/4); stuff count 4 + CRC (17 for
//    len <= 16, else 21) with one fixed stuff bit per started 4 bits; CRC delimiter 1.
TEST(FdFrame, FrameLengthsAndDlcCodes) {
  for (std::uint32_t n = 0; n <= 8; ++n) {
    EXPECT_TRUE(is_frame_length(n, false)) << n;
    EXPECT_EQ(dlc_length(n), n);
  }
  EXPECT_FALSE(is_frame_length(12, false));  // classic CAN: 8 bytes at most
  const std::uint32_t fd[] = {12, 16, 20, 24, 32, 48, 64};
  for (std::uint32_t code = 9; code <= 15; ++code) EXPECT_EQ(dlc_length(code), fd[code - 9]) << code;
  for (std::uint32_t n = 9; n <= 70; ++n) {
    const bool expected = std::find(std::begin(fd), std::end(fd), n) != std::end(fd);
    EXPECT_EQ(is_frame_length(n, true), expected) << n;
  }
}

TEST(FdFrame, BitsExtended64) {
  // nominal: 36 + floor(35/4) = 36 + 8 = 44, + 12 = 56.
  // data: 5 + 512 = 517, + floor(516/4) = 129 -> 646; + 4 + 21 = 671; + ceil(25/4) = 7 -> 678; + 1 = 679.
  const FdFrameBits bits = fd_frame_bits(64, CanIdFormat::extended29);
  EXPECT_EQ(bits.nominal_bits, 56u);
  EXPECT_EQ(bits.data_bits, 679u);
}

TEST(FdFrame, BitsStandard8) {
  // nominal: 17 + floor(16/4) = 21, + 12 = 33.
  // data: 5 + 64 = 69, + floor(68/4) = 17 -> 86; + 4 + 17 = 107; + ceil(21/4) = 6 -> 113; + 1 = 114.
  const FdFrameBits bits = fd_frame_bits(8, CanIdFormat::standard11);
  EXPECT_EQ(bits.nominal_bits, 33u);
  EXPECT_EQ(bits.data_bits, 114u);
}

TEST(FdFrame, CrcLengthSwitchesAbove16Bytes) {
  // 16 B: 5 + 128 = 133, + 33 = 166; + 4 + 17 + 6 + 1 = 194.
  EXPECT_EQ(fd_frame_bits(16, CanIdFormat::extended29).data_bits, 194u);
  // 20 B: 5 + 160 = 165, + 41 = 206; + 4 + 21 + 7 + 1 = 239.
  EXPECT_EQ(fd_frame_bits(20, CanIdFormat::extended29).data_bits, 239u);
  // 9 B is sent as 12 B: 5 + 96 = 101, + 25 = 126; + 4 + 17 + 6 + 1 = 154.
  EXPECT_EQ(fd_frame_bits(9, CanIdFormat::extended29).data_bits, 154u);
  EXPECT_EQ(fd_frame_bits(9, CanIdFormat::extended29).data_bits, fd_frame_bits(12, CanIdFormat::extended29).data_bits);
}

TEST(FdFrame, FrameTime64BExtended500k2M) {
  CanSegmentProperties bus;
  bus.fd = true;
  bus.bitrate = BitRate{500'000};         // 2 us per nominal bit
  bus.data_bitrate = BitRate{2'000'000};  // 0.5 us per data bit
  // 56 * 2 us + 679 * 0.5 us = 112 us + 339.5 us = 451.5 us.
  EXPECT_EQ(frame_time(bus, 64, CanIdFormat::extended29), Nanos(451'500));
  EXPECT_EQ(max_frame_payload(bus), 64u);
}

TEST(FdFrame, FrameTime8BStandard500k2M) {
  CanSegmentProperties bus;
  bus.fd = true;
  bus.bitrate = BitRate{500'000};
  bus.data_bitrate = BitRate{2'000'000};
  // 33 * 2 us + 114 * 0.5 us = 66 us + 57 us = 123 us.
  EXPECT_EQ(frame_time(bus, 8, CanIdFormat::standard11), Nanos(123'000));
}

TEST(FdFrame, FrameTime64BExtended1M5M) {
  CanSegmentProperties bus;
  bus.fd = true;
  bus.bitrate = BitRate{1'000'000};
  bus.data_bitrate = BitRate{5'000'000};
  // 56 * 1 us + 679 * 0.2 us = 56 us + 135.8 us = 191.8 us.
  EXPECT_EQ(frame_time(bus, 64, CanIdFormat::extended29), Nanos(191'800));
}

TEST(FdFrame, NoDataRateMeansNominalRate) {
  CanSegmentProperties bus;
  bus.fd = true;
  bus.bitrate = BitRate{500'000};
  bus.data_bitrate = BitRate{0};
  // (56 + 679) * 2 us = 1.47 ms.
  EXPECT_EQ(frame_time(bus, 64, CanIdFormat::extended29), Nanos(1'470'000));
}

// ---------------------------------------------------------------- response-time analysis

CanBusTiming timing_with_bit(Nanos bit, CanFaultHypothesis errors = {}) {
  return CanBusTiming{bit, Nanos(31 * bit.count()), errors};
}

// Davis, Burns, Bril, Lukkien 2007, section 3 (the refuted example): A, B, C with C = 1 ms and
// T = 2.5, 3.5, 3.5 ms, priorities in that order; tau_bit = 1 us (the analysis adds tau_bit
// inside the ceiling, so a zero tau_bit would miss the higher-priority instance at t = 0).
//  A: B = 1 ms (a lower frame), no hp: w = 1 ms, R = 2 ms.
//  B: B = 1 ms, hp = {A}: busy period 5 ms, Q = 2.
//     q=0: w = 1 + ceil(2.001/2.5)*1 = 2 -> R = 3 ms; q=1: w = 2 + ceil(3.001/2.5)*1 = 4 ->
//     R = 4 - 3.5 + 1 = 1.5 ms. R_B = 3 ms.
//  C: B = 0, hp = {A, B}: busy period t = 1, 3, 4, 6, 7 -> 7 ms, Q = ceil(7/3.5) = 2.
//     q=0: w = 2 -> R = 3 ms (what the original analysis stops at).
//     q=1: w = 1 + ... -> 3, 4, 5, 6, 6 -> R = 6 - 3.5 + 1 = 3.5 ms. R_C = 3.5 ms.
TEST(ResponseTime, DavisWorkedExample) {
  const std::array<CanStream, 3> streams{{{1, Nanos(1ms), Nanos(2500us), Nanos(0)},
                                          {2, Nanos(1ms), Nanos(3500us), Nanos(0)},
                                          {3, Nanos(1ms), Nanos(3500us), Nanos(0)}}};
  const auto r = response_times(streams, timing_with_bit(Nanos(1us)));
  ASSERT_EQ(r.size(), 3u);
  ASSERT_TRUE(r[0] && r[1] && r[2]);
  EXPECT_EQ(*r[0], Nanos(2ms));
  EXPECT_EQ(*r[1], Nanos(3ms));
  EXPECT_EQ(*r[2], Nanos(3500us));  // second instance; the original analysis claimed 3.0 ms
  EXPECT_NE(*r[2], Nanos(3ms));
  EXPECT_NEAR(utilization(streams), 1.0 / 2.5 + 2.0 / 3.5, 1e-12);
}

TEST(ResponseTime, InputOrderIsKept) {
  // Same streams in reverse order: results follow the input, priorities follow can_id.
  const std::array<CanStream, 3> streams{{{3, Nanos(1ms), Nanos(3500us), Nanos(0)},
                                          {2, Nanos(1ms), Nanos(3500us), Nanos(0)},
                                          {1, Nanos(1ms), Nanos(2500us), Nanos(0)}}};
  const auto r = response_times(streams, timing_with_bit(Nanos(1us)));
  EXPECT_EQ(r[0], Nanos(3500us));
  EXPECT_EQ(r[1], Nanos(3ms));
  EXPECT_EQ(r[2], Nanos(2ms));
}

TEST(ResponseTime, SingleStreamIsItsFrameTime) {
  const std::array<CanStream, 1> streams{{{1, Nanos(320us), Nanos(10ms), Nanos(0)}}};
  EXPECT_EQ(response_times(streams, timing_with_bit(Nanos(2us)))[0], Nanos(320us));
}

// Blocking: a higher-priority 0.5 ms frame waits behind a lower-priority 2 ms frame that just
// started: R = B + C = 2 + 0.5 = 2.5 ms. The lower one: w = ceil(0.001/10)*0.5 = 0.5, R = 2.5 ms.
TEST(ResponseTime, BlockingByLowerPriorityLongerFrame) {
  const std::array<CanStream, 2> streams{
      {{1, Nanos(500us), Nanos(10ms), Nanos(0)}, {2, Nanos(2ms), Nanos(10ms), Nanos(0)}}};
  const auto r = response_times(streams, timing_with_bit(Nanos(1us)));
  EXPECT_EQ(r[0], Nanos(2500us));
  EXPECT_EQ(r[1], Nanos(2500us));
  // Without the long frame the high-priority stream is sent at once.
  EXPECT_EQ(response_times(std::span(streams).first(1), timing_with_bit(Nanos(1us)))[0], Nanos(500us));
}

// Fault hypothesis: at most N error frames per window W; each costs 31 bit-times plus the
// retransmission of the longest frame of priority >= m. One stream C = 1 ms, T = 10 ms,
// tau_bit = 1 us: one error per 100 ms adds 31 us + 1 ms: R = 1 + 1.031 = 2.031 ms; two errors
// add twice that: R = 3.062 ms.
TEST(ResponseTime, ErrorTermAddsRecoveryTime) {
  const std::array<CanStream, 1> streams{{{1, Nanos(1ms), Nanos(10ms), Nanos(0)}}};
  EXPECT_EQ(response_times(streams, timing_with_bit(Nanos(1us)))[0], Nanos(1ms));
  EXPECT_EQ(response_times(streams, timing_with_bit(Nanos(1us), {1, Nanos(100ms)}))[0], Nanos(2'031'000));
  EXPECT_EQ(response_times(streams, timing_with_bit(Nanos(1us), {2, Nanos(100ms)}))[0], Nanos(3'062'000));
  // max_per_window 0 disables the term whatever the window.
  EXPECT_EQ(response_times(streams, timing_with_bit(Nanos(1us), {0, Nanos(1ms)}))[0], Nanos(1ms));
}

TEST(ResponseTime, ErrorTermRetransmitsLongestHigherOrEqualFrame) {
  // Low stream (C = 0.5 ms) under a high stream (C = 1 ms, T = 10 ms); one error per 100 ms.
  // Low: w = E(w + 0.5) + ceil((w + 0.001)/10) * 1: w0 = 0 -> 1.031 + 1 = 2.031 -> stays.
  // R = 2.031 + 0.5 = 2.531 ms (the error retransmits the 1 ms frame, not the 0.5 ms one).
  const std::array<CanStream, 2> streams{
      {{1, Nanos(1ms), Nanos(10ms), Nanos(0)}, {2, Nanos(500us), Nanos(10ms), Nanos(0)}}};
  const auto r = response_times(streams, timing_with_bit(Nanos(1us), {1, Nanos(100ms)}));
  EXPECT_EQ(r[1], Nanos(2'531'000));
}

TEST(ResponseTime, OverloadedBusIsUnbounded) {
  // Two 1 ms frames every 1.5 ms: 133 % load. The higher one still has a bound:
  // B = 1 ms, busy period 3 ms, Q = 2; q=0: R = 1 + 1 = 2 ms; q=1: R = 2 - 1.5 + 1 = 1.5 ms.
  const std::array<CanStream, 2> streams{
      {{1, Nanos(1ms), Nanos(1500us), Nanos(0)}, {2, Nanos(1ms), Nanos(1500us), Nanos(0)}}};
  const auto r = response_times(streams, timing_with_bit(Nanos(1us)));
  EXPECT_EQ(r[0], Nanos(2ms));
  EXPECT_FALSE(r[1].has_value());
  // A stream that alone fills the bus (C = T) is unbounded too.
  const std::array<CanStream, 1> full{{{1, Nanos(1ms), Nanos(1ms), Nanos(0)}}};
  EXPECT_FALSE(response_times(full, timing_with_bit(Nanos(1us)))[0].has_value());
  // So is one overloaded by the fault hypothesis: 1 + 1.031 errors per 1 ms window > 100 %.
  const std::array<CanStream, 1> light{{{1, Nanos(1ms), Nanos(10ms), Nanos(0)}}};
  EXPECT_FALSE(response_times(light, timing_with_bit(Nanos(1us), {1, Nanos(1ms)}))[0].has_value());
}

TEST(ResponseTime, JitterOfOwnAndHigherStreams) {
  // Own jitter adds in full: R = J + w + C = 3 + 0 + 1 = 4 ms.
  const std::array<CanStream, 1> own{{{1, Nanos(1ms), Nanos(10ms), Nanos(3ms)}}};
  EXPECT_EQ(response_times(own, timing_with_bit(Nanos(1us)))[0], Nanos(4ms));
  // Jitter of a higher stream (C = 1, T = 5, J = 4.5) lets two of its frames hit the low one:
  // w = 0 -> ceil(4.501/5) = 1 -> ceil(5.501/5) = 2 -> 2; R = 2 + 1 = 3 ms (2 ms without jitter).
  const std::array<CanStream, 2> hp{
      {{1, Nanos(1ms), Nanos(5ms), Nanos(4500us)}, {2, Nanos(1ms), Nanos(100ms), Nanos(0)}}};
  EXPECT_EQ(response_times(hp, timing_with_bit(Nanos(1us)))[1], Nanos(3ms));
  const std::array<CanStream, 2> no_jitter{
      {{1, Nanos(1ms), Nanos(5ms), Nanos(0)}, {2, Nanos(1ms), Nanos(100ms), Nanos(0)}}};
  EXPECT_EQ(response_times(no_jitter, timing_with_bit(Nanos(1us)))[1], Nanos(2ms));
}

// ---------------------------------------------------------------- incremental analysis

// Fifty 100 us frames with identifiers 10, 20, ..., 500, every 100 ms, plus one newcomer.
std::vector<CanStream> fifty_and(std::optional<CanStream> newcomer) {
  std::vector<CanStream> streams;
  for (std::uint32_t id = 10; id <= 500; id += 10)
    streams.push_back(CanStream{id, Nanos(100us), Nanos(100ms), Nanos(0)});
  if (newcomer) streams.push_back(*newcomer);
  return streams;
}

TEST(IncrementalResponseTime, NewcomerReexaminesOnlyEqualOrLowerPriority) {
  const CanBusTiming timing = timing_with_bit(Nanos(2us), {1, Nanos(100ms)});
  const auto before_streams = fifty_and(std::nullopt);
  const CanBusAnalysis before(before_streams, timing);
  EXPECT_EQ(before.analysed(), 50u);
  struct Case {
    std::uint32_t id;
    Nanos transmission;
    std::size_t analysed;
  };
  // Lowest priority: itself, and the previous lowest whose blocking it becomes. Middle: itself
  // and the 25 below it. Highest: everyone. A longer frame below all others: it blocks them all.
  for (const Case c : {Case{1000, Nanos(100us), 2}, Case{255, Nanos(100us), 26}, Case{5, Nanos(100us), 51},
                       Case{1000, Nanos(200us), 51}}) {
    const auto streams = fifty_and(CanStream{c.id, c.transmission, Nanos(50ms), Nanos(0)});
    const CanBusAnalysis incremental(streams, timing, &before);
    EXPECT_EQ(incremental.analysed(), c.analysed) << c.id;
    EXPECT_EQ(incremental.results(), response_times(streams, timing)) << c.id;
  }
  // Another bus timing: nothing is reused.
  EXPECT_EQ(CanBusAnalysis(before_streams, timing_with_bit(Nanos(1us)), &before).analysed(), 50u);
}

TEST(IncrementalResponseTime, ChangedJitterReexaminesFromThatStreamDown) {
  const CanBusTiming timing = timing_with_bit(Nanos(2us));
  const auto streams = fifty_and(std::nullopt);
  const CanBusAnalysis before(streams, timing);
  auto jittered = streams;
  jittered[39].jitter = Nanos(3ms);  // id 400: itself and the ten below
  const CanBusAnalysis after(jittered, timing, &before);
  EXPECT_EQ(after.analysed(), 11u);
  EXPECT_EQ(after.results(), response_times(jittered, timing));
}

// ---------------------------------------------------------------- identifiers (DESIGN.md §5)

TEST(CanWire, IdentifierLayout) {
  // priority << 21 | node << 14 | etag: 0x12 << 21 = 0x2400000, 1 << 14 = 0x4000, etag 0x3FFF.
  EXPECT_EQ(encode_can_id(CanIdentifier{0x12, 1, 16383}), 0x2407FFFu);
  EXPECT_EQ(encode_can_id(CanIdentifier{0xFF, 127, 16383}), 0x1FFFFFFFu);  // all 29 bits
  EXPECT_EQ(encode_can_id(CanIdentifier{0, 0, 0}), 0u);
  EXPECT_EQ(encode_can_id(CanIdentifier{0, 5, 101}), (5u << 14) | 101u);
  EXPECT_EQ(decode_can_id(0x2407FFF), (CanIdentifier{0x12, 1, 16383}));
  for (const CanIdentifier id :
       {CanIdentifier{0xF0, 42, 2}, CanIdentifier{0x0F, 127, 3}, CanIdentifier{0x80, 0, 9999}}) {
    EXPECT_EQ(decode_can_id(encode_can_id(id)), id);
  }
  // A lower priority number wins arbitration whatever node and etag.
  EXPECT_LT(encode_can_id(CanIdentifier{0x0F, 127, 16383}), encode_can_id(CanIdentifier{0x10, 0, 0}));
}

TEST(CanWire, PriorityBands) {
  EXPECT_EQ(kHrtBand.first, 0x00);
  EXPECT_EQ(kHrtBand.last, 0x0F);
  EXPECT_EQ(kSrtBand.first, 0x10);
  EXPECT_EQ(kSrtBand.last, 0xEF);
  EXPECT_EQ(kNrtBand.first, 0xF0);
  EXPECT_EQ(kNrtBand.last, 0xFF);
  EXPECT_EQ(band_of(ChannelClass::hrt).first, 0x00);
  EXPECT_EQ(band_of(ChannelClass::srt).first, 0x10);
  EXPECT_EQ(band_of(ChannelClass::nrt).first, 0xF0);
  // One level per rank while the band has room.
  EXPECT_EQ(band_priority(ChannelClass::hrt, 0, 1), 0x00);
  EXPECT_EQ(band_priority(ChannelClass::hrt, 15, 16), 0x0F);
  EXPECT_EQ(band_priority(ChannelClass::srt, 0, 3), 0x10);
  EXPECT_EQ(band_priority(ChannelClass::srt, 2, 3), 0x12);
  EXPECT_EQ(band_priority(ChannelClass::srt, 223, 224), 0xEF);
  EXPECT_EQ(band_priority(ChannelClass::nrt, 0, 2), 0xF0);
  EXPECT_EQ(band_priority(ChannelClass::nrt, 15, 16), 0xFF);
  // More channels than levels: spread evenly, never outside the band.
  EXPECT_EQ(band_priority(ChannelClass::hrt, 1, 32), 0x00);      // 1 * 16 / 32 = 0
  EXPECT_EQ(band_priority(ChannelClass::hrt, 2, 32), 0x01);      // 2 * 16 / 32 = 1
  EXPECT_EQ(band_priority(ChannelClass::hrt, 31, 32), 0x0F);     // 31 * 16 / 32 = 15
  EXPECT_EQ(band_priority(ChannelClass::srt, 999, 1000), 0xEF);  // 0x10 + 999 * 224 / 1000
  EXPECT_EQ(band_priority(ChannelClass::nrt, 99, 100), 0xFF);
}

TEST(CanWire, Fragments) {
  EXPECT_EQ(fragments_needed(8, 8), 1u);
  EXPECT_EQ(fragments_needed(0, 8), 1u);
  EXPECT_EQ(fragments_needed(9, 8), 2u);  // 6 data bytes per fragment after the 2-byte header
  EXPECT_EQ(fragments_needed(12, 8), 2u);
  EXPECT_EQ(fragments_needed(13, 8), 3u);
  EXPECT_EQ(fragments_needed(256, 8), 43u);  // ceil(256 / 6)
  EXPECT_EQ(fragments_needed(64, 64), 1u);
  EXPECT_EQ(fragments_needed(65, 64), 2u);  // 62 per fragment
  EXPECT_EQ(kFragmentHeaderBytes, 2u);
}

TEST(CanWire, ReservedEtags) {
  EXPECT_EQ(kMaxEtag, 16383);
  EXPECT_EQ(kHighestReservedEtag, 100);
  EXPECT_EQ(kEtagGetEtag, 2);
  EXPECT_EQ(kEtagSupplyEtag, 3);
}

}  // namespace
}  // namespace cosmic

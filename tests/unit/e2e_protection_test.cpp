// End-to-end protection of DBC frames (issue 35; cosmic/e2e_protection.hpp): CRC-8 SAE J1850
// against the check values of AUTOSAR's CRC library specification, profile 1's CRC over the data
// ID and the frame against python3-crcmod's (values below computed with crcmod.mkCrcFun(0x11D,
// initCrc=0, xorOut=0), not with this code), the counter's range and wrap, what make() refuses, and
// the receiver's gaps and repeats.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cosmic/dbc.hpp"
#include "cosmic/e2e_protection.hpp"

#include "dbc_test_support.hpp"

namespace cosmic {
namespace {

using Bytes = std::vector<std::uint8_t>;

// BrakeStatus: CRC in byte 0, the counter in the low nibble of byte 1, Pressure in bytes 2-3.
// Wide: an 8-bit counter in byte 3. Odd: signals make() refuses.
constexpr std::string_view kE2eDbc = R"dbc(BO_ 432 BrakeStatus: 4 Ecu
 SG_ Crc : 0|8@1+ (1,0) [0|255] "" Gateway
 SG_ Counter : 8|4@1+ (1,0) [0|14] "" Gateway
 SG_ Flags : 12|4@1+ (1,0) [0|15] "" Gateway
 SG_ Pressure : 16|16@1+ (0.1,0) [0|6553.5] "bar" Gateway
BO_ 433 Wide: 4 Ecu
 SG_ Value : 0|16@1+ (1,0) [0|0] "" Gateway
 SG_ Check : 23|8@0+ (1,0) [0|0] "" Gateway
 SG_ Alive : 24|8@1+ (1,0) [0|0] "" Gateway
BO_ 434 Odd: 8 Ecu
 SG_ Mux M : 0|8@1+ (1,0) [0|0] "" Gateway
 SG_ MuxedCrc m1 : 8|8@1+ (1,0) [0|0] "" Gateway
 SG_ ShortCrc : 16|6@1+ (1,0) [0|0] "" Gateway
 SG_ SkewedCrc : 27|8@1+ (1,0) [0|0] "" Gateway
 SG_ SignedCounter : 40|4@1- (1,0) [0|0] "" Gateway
 SG_ OneBit : 44|1@1+ (1,0) [0|0] "" Gateway
 SG_ Crc : 48|8@1+ (1,0) [0|0] "" Gateway
 SG_ Overlapping : 52|4@1+ (1,0) [0|0] "" Gateway
 SG_ Counter : 56|4@1+ (1,0) [0|0] "" Gateway
BO_ 435 Tiny: 1 Ecu
 SG_ Crc : 0|8@1+ (1,0) [0|0] "" Gateway
)dbc";

const DbcMessage& e2e_message(const std::string& name) {
  static const DbcFile file = parse_dbc(kE2eDbc);
  return test::message_named(file, name);
}

E2eProtection brake_protection(E2eDataIdMode mode = E2eDataIdMode::both, std::uint16_t data_id = 0x0123) {
  Result<E2eProtection> made =
      E2eProtection::make(e2e_message("BrakeStatus"), E2eSpec{"Counter", "Crc", data_id, mode});
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.error().text);
  return std::move(made).value();
}

TEST(E2eProtectionTest, Crc8J1850HasAutosarsCheckValues) {
  // AUTOSAR SWS CRC Library, CRC8 (SAE J1850): start value 0xFF, final XOR 0xFF.
  const std::vector<std::pair<Bytes, std::uint8_t>> checks = {
      {{0x00, 0x00, 0x00, 0x00}, 0x59},
      {{0xF2, 0x01, 0x83}, 0x37},
      {{0x0F, 0xAA, 0x00, 0x55}, 0x79},
      {{0x00, 0xFF, 0x55, 0x11}, 0xB8},
      {{0x33, 0x22, 0x55, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF}, 0xCB},
      {{0x92, 0x6B, 0x55}, 0x8C},
      {{0xFF, 0xFF, 0xFF, 0xFF}, 0x74},
      {{'1', '2', '3', '4', '5', '6', '7', '8', '9'}, 0x4B},
  };
  for (const auto& [data, crc] : checks) EXPECT_EQ(crc8_j1850(data, 0xFF) ^ 0xFF, crc);
}

TEST(E2eProtectionTest, ProfileOnesCrcCoversTheDataIdThenTheFrameButItsCrcByte) {
  const E2eProtection e2e = brake_protection();
  EXPECT_EQ(e2e.counter_modulus(), 15u);
  EXPECT_EQ(e2e.frame_length(), 4u);
  Bytes frame = {0x00, 0x00, 0x34, 0x12};  // Pressure 466.0 bar
  e2e.protect(frame, 5);
  // crcmod over 23 01 05 34 12 (data ID low, high, then bytes 1..3) = 0x70.
  EXPECT_EQ(frame, (Bytes{0x70, 0x05, 0x34, 0x12}));
  const E2eReading reading = e2e.check(frame);
  EXPECT_TRUE(reading.intact);
  EXPECT_EQ(reading.counter, 5u);
}

TEST(E2eProtectionTest, DataIdModesTakeTheirBytesOfTheId) {
  Bytes low = {0x00, 0x00, 0x34, 0x12};
  brake_protection(E2eDataIdMode::low).protect(low, 5);
  EXPECT_EQ(low[0], 0x62);  // crcmod over 23 05 34 12
  Bytes even = {0x00, 0x00, 0x34, 0x12};
  brake_protection(E2eDataIdMode::alt).protect(even, 4);
  EXPECT_EQ(even[0], 0xED);  // crcmod over 23 04 34 12: the low byte with an even counter
  Bytes odd = {0x00, 0x00, 0x34, 0x12};
  brake_protection(E2eDataIdMode::alt).protect(odd, 5);
  EXPECT_EQ(odd[0], 0x0F);  // crcmod over 01 05 34 12: the high byte with an odd one
}

TEST(E2eProtectionTest, AFourBitCounterRunsToFourteenAndFifteenIsInvalid) {
  const E2eProtection e2e = brake_protection();
  Bytes frame = {0x00, 0xA0, 0x34, 0x12};  // Flags (the high nibble) stay
  e2e.protect(frame, 15);                  // 15 mod 15: 0
  EXPECT_EQ(frame[1], 0xA0);
  e2e.protect(frame, 29);
  EXPECT_EQ(frame[1], 0xAE);
  EXPECT_TRUE(e2e.check(frame).intact);
  frame[1] = 0xAF;  // counter 15, with the CRC it would have
  frame[0] = e2e.crc_of(frame, 15);
  EXPECT_FALSE(e2e.check(frame).intact);
}

TEST(E2eProtectionTest, AnyFlippedBitOrAnotherDataIdIsCaught) {
  const E2eProtection e2e = brake_protection();
  Bytes frame = {0x00, 0x00, 0x34, 0x12};
  e2e.protect(frame, 3);
  for (std::size_t bit = 0; bit < frame.size() * 8; ++bit) {
    Bytes flipped = frame;
    flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(e2e.check(flipped).intact) << "bit " << bit;
  }
  EXPECT_FALSE(brake_protection(E2eDataIdMode::both, 0x0124).check(frame).intact);
  EXPECT_FALSE(e2e.check(Bytes(frame.begin(), frame.end() - 1)).intact);  // shorter than the message
  Bytes padded = frame;
  padded.resize(8, 0xAA);  // CAN FD padding beyond the message is not covered
  EXPECT_TRUE(e2e.check(padded).intact);
}

TEST(E2eProtectionTest, AWiderCounterWrapsAtItsBitsAndAMotorolaCrcByteIsItsByte) {
  Result<E2eProtection> made =
      E2eProtection::make(e2e_message("Wide"), E2eSpec{"Alive", "Check", 7, E2eDataIdMode::low});
  ASSERT_TRUE(made.ok()) << made.error().text;
  const E2eProtection& e2e = made.value();
  EXPECT_EQ(e2e.counter_modulus(), 256u);
  Bytes frame = {0x01, 0x02, 0x00, 0x00};
  e2e.protect(frame, 256 + 9);
  EXPECT_EQ(frame[3], 9);
  EXPECT_EQ(frame[2], e2e.crc_of(frame, 9));
  EXPECT_TRUE(e2e.check(frame).intact);
}

TEST(E2eProtectionTest, MakeRefusesWhatCannotBeProtectedAndSaysWhy) {
  const auto refused = [](const std::string& msg, const std::string& counter, const std::string& crc) {
    Result<E2eProtection> made = E2eProtection::make(e2e_message(msg), E2eSpec{counter, crc, 1, E2eDataIdMode::both});
    return made.ok() ? std::string("accepted") : made.error().text;
  };
  EXPECT_EQ(refused("Odd", "Counter", "Nothing"), "no signal Nothing in message Odd for the CRC");
  EXPECT_EQ(refused("Odd", "Counter", "MuxedCrc"),
            "the CRC signal MuxedCrc takes part in multiplexing; it must be in every frame");
  EXPECT_EQ(refused("Odd", "Counter", "ShortCrc"),
            "the CRC signal ShortCrc does not fill one whole byte of the frame (6 bits at start bit 16); CRC-8 "
            "needs one byte of its own");
  EXPECT_EQ(refused("Odd", "Counter", "SkewedCrc"),
            "the CRC signal SkewedCrc does not fill one whole byte of the frame (8 bits at start bit 27); CRC-8 "
            "needs one byte of its own");
  EXPECT_EQ(refused("Odd", "SignedCounter", "Crc"), "the counter signal SignedCounter is not an unsigned integer");
  EXPECT_EQ(refused("Odd", "OneBit", "Crc"),
            "the counter signal OneBit has 1 bits; a counter has 2 to 16 (4 for AUTOSAR profile 1)");
  EXPECT_EQ(refused("Odd", "Overlapping", "Crc"), "the counter signal Overlapping overlaps the CRC signal Crc");
  EXPECT_EQ(refused("Odd", "Crc", "Crc"), "the counter and the CRC are one signal, Crc");
  EXPECT_EQ(refused("Tiny", "Crc2", "Crc"), "no signal Crc2 in message Tiny for the counter");
  EXPECT_EQ(refused("Odd", "Counter", "Crc"), "accepted");
}

TEST(E2eProtectionTest, ThePayloadMessageLeavesTheCounterAndCrcOut) {
  const DbcMessage payload = e2e_payload_message(e2e_message("BrakeStatus"), E2eSpec{"Counter", "Crc", 0, {}});
  ASSERT_EQ(payload.signals.size(), 2u);
  EXPECT_EQ(payload.signals[0].name, "Flags");
  EXPECT_EQ(payload.signals[1].name, "Pressure");
  EXPECT_EQ(payload.length, 4u);
}

TEST(E2eProtectionTest, TheReceiverCountsGapsAndRepeatsAcrossTheWrap) {
  EXPECT_EQ(e2e_step(std::nullopt, 7, 15).omitted, 0u);  // the first frame judges nothing
  EXPECT_FALSE(e2e_step(std::nullopt, 7, 15).repeated);
  EXPECT_EQ(e2e_step(7u, 8, 15).omitted, 0u);
  EXPECT_EQ(e2e_step(14u, 0, 15).omitted, 0u);  // 14 -> 0: the next one
  EXPECT_EQ(e2e_step(13u, 1, 15).omitted, 2u);  // 14 and 0 missing
  EXPECT_TRUE(e2e_step(9u, 9, 15).repeated);
  EXPECT_EQ(e2e_step(9u, 8, 15).omitted, 13u);  // an older frame looks like the longest gap
  EXPECT_EQ(e2e_step(255u, 0, 256).omitted, 0u);
}

}  // namespace
}  // namespace cosmic

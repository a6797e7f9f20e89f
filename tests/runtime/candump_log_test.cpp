// The candump -l log format (cosmic/candump_log.hpp) against lines as can-utils writes them
// (candump.c's log line, lib.c's sprint_canframe): standard, extended, remote, CAN FD and error
// frames; the time's fixed digits; frames taken from struct can_frame / canfd_frame bytes; the
// parser's acceptance of what canplayer accepts and its refusals, each with its reason.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/candump_log.hpp"

namespace cosmic {
namespace {

constexpr std::int64_t kTime = 1'700'000'000'123'456'789;  // (1700000000.123456)

CandumpFrame classic_frame(std::uint32_t can_id, std::initializer_list<std::uint8_t> data) {
  CandumpFrame f;
  f.can_id = can_id;
  f.len = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), f.data.begin());
  return f;
}

std::string line_of(const CandumpFrame& frame, std::string_view interface = "can0", std::int64_t utc_ns = kTime) {
  std::string out;
  append_candump_line(utc_ns, interface, frame, out);
  return out;
}

TEST(CandumpLog, WritesLinesAsCandumpDoes) {
  EXPECT_EQ(line_of(classic_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})), "(1700000000.123456) can0 123#DEADBEEF\n");
  EXPECT_EQ(line_of(classic_frame(0x7FF, {})), "(1700000000.123456) can0 7FF#\n");
  EXPECT_EQ(line_of(classic_frame(0x00A0412C | kCandumpEffFlag, {0x01})), "(1700000000.123456) can0 00A0412C#01\n");
  // Seconds zero-padded to ten digits, microseconds to six; the nanoseconds cut, not rounded.
  EXPECT_EQ(line_of(classic_frame(0x001, {}), "vcan0", 5'000'999'999), "(0000000005.000999) vcan0 001#\n");
  EXPECT_EQ(line_of(classic_frame(0x001, {}), "vcan0", -1), "(0000000000.000000) vcan0 001#\n");
}

TEST(CandumpLog, RemoteFramesShowTheirDlcWhenNotZero) {
  CandumpFrame remote = classic_frame(0x123 | kCandumpRtrFlag, {});
  EXPECT_EQ(line_of(remote), "(1700000000.123456) can0 123#R\n");
  remote.len = 4;
  EXPECT_EQ(line_of(remote), "(1700000000.123456) can0 123#R4\n");
  remote.can_id = 0x1ABCDE0 | kCandumpEffFlag | kCandumpRtrFlag;
  EXPECT_EQ(line_of(remote), "(1700000000.123456) can0 01ABCDE0#R4\n");
}

TEST(CandumpLog, FdFramesCarryTheirFlagsNibble) {
  CandumpFrame fd = classic_frame(0x123, {0x11, 0x22, 0x33});
  fd.fd = true;
  EXPECT_EQ(line_of(fd), "(1700000000.123456) can0 123##0112233\n");
  fd.flags = 0x1 | 0x2;  // BRS, ESI
  fd.len = 12;
  EXPECT_EQ(line_of(fd), "(1700000000.123456) can0 123##3112233000000000000000000\n");
  fd.len = 64;
  std::string text;
  append_candump_frame(fd, text);
  EXPECT_EQ(text.size(), 3 + 2 + 1 + 128u);
}

TEST(CandumpLog, ErrorFramesShowTheErrorFlagAndClass) {
  // CAN_ERR_FLAG | CAN_ERR_CRTL, data[1] = CAN_ERR_CRTL_RX_WARNING, as candump -l logs it.
  const CandumpFrame error = classic_frame(kCandumpErrFlag | 0x4, {0, 0x04, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(line_of(error), "(1700000000.123456) can0 20000004#0004000000000000\n");
  const auto parsed = parse_candump_line(line_of(error));
  ASSERT_TRUE(parsed) << parsed.error().text;
  EXPECT_EQ(parsed.value().frame, error);
}

TEST(CandumpLog, TakesFramesFromSocketCanBytes) {
  std::array<std::uint8_t, kCanFdMtu> wire{};
  const std::uint32_t id = 0x12345678 | kCandumpEffFlag;
  std::memcpy(wire.data(), &id, 4);
  wire[4] = 2;     // can_dlc
  wire[5] = 0xFF;  // padding in can_frame: not shown
  wire[8] = 0xAB;
  wire[9] = 0xCD;
  wire[10] = 0xEE;  // beyond the length: not shown
  auto classic = candump_frame_from_wire(std::span(wire).first(kCanMtu));
  ASSERT_TRUE(classic);
  EXPECT_EQ(line_of(*classic), "(1700000000.123456) can0 12345678#ABCD\n");
  auto fd = candump_frame_from_wire(wire);
  ASSERT_TRUE(fd);
  EXPECT_EQ(line_of(*fd, "vcan1"), "(1700000000.123456) vcan1 12345678##FABCD\n");
  EXPECT_FALSE(candump_frame_from_wire(std::span(wire).first(20)));
  // Back to bytes, as canplayer writes them: the same frame again.
  std::array<std::uint8_t, kCanFdMtu> again{};
  ASSERT_EQ(candump_frame_to_wire(*fd, again), kCanFdMtu);
  EXPECT_EQ(candump_frame_from_wire(again), fd);
  ASSERT_EQ(candump_frame_to_wire(*classic, again), kCanMtu);
  EXPECT_EQ(candump_frame_from_wire(std::span(again).first(kCanMtu)), classic);
}

TEST(CandumpLog, ParsesWhatCanplayerReads) {
  auto line = parse_candump_line("(1700000000.123456) can0 123#DEADBEEF\n");
  ASSERT_TRUE(line) << line.error().text;
  EXPECT_EQ(line.value().utc_us, 1'700'000'000'123'456);
  EXPECT_EQ(line.value().interface, "can0");
  EXPECT_EQ(line.value().frame, classic_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF}));
  // candump pads the interface when it listens on several; lower case and separators as lib.c reads them.
  line = parse_candump_line("(0000000001.000002)  can1 1abcdef0#de.ad\r\n");
  ASSERT_TRUE(line) << line.error().text;
  EXPECT_EQ(line.value().utc_us, 1'000'002);
  EXPECT_EQ(line.value().interface, "can1");
  EXPECT_EQ(line.value().frame, classic_frame(0x1ABCDEF0 | kCandumpEffFlag, {0xDE, 0xAD}));
  line = parse_candump_line("(1.000000) can0 123##1.11.22");
  ASSERT_TRUE(line) << line.error().text;
  EXPECT_TRUE(line.value().frame.fd);
  EXPECT_EQ(line.value().frame.flags, 1);
  EXPECT_EQ(line.value().frame.len, 2);
  line = parse_candump_line("(1.000000) can0 123#r7");
  ASSERT_TRUE(line) << line.error().text;
  EXPECT_EQ(line.value().frame.can_id, 0x123 | kCandumpRtrFlag);
  EXPECT_EQ(line.value().frame.len, 7);
}

TEST(CandumpLog, RefusesWhatIsNoLogLine) {
  const std::pair<const char*, const char*> bad[] = {
      {"", "starts with '('"},
      {"DROPCOUNT: dropped 1 CAN frame on 'can0' socket", "starts with '('"},
      {"(1700000000) can0 123#", "not (SECONDS.MICROSECONDS)"},
      {"(1700000000.12345) can0 123#", "not 6 decimal digits"},
      {"(17000x0000.123456) can0 123#", "seconds"},
      {"(1700000000.123456)can0 123#", "no space after the time"},
      {"(1700000000.123456) can0", "no frame"},
      {"(1700000000.123456) an_interface_name_too_long 123#", "1 to 15 characters"},
      {"(1700000000.123456) can0 123#00 extra", "more than time, interface and frame"},
      {"(1700000000.123456) can0 12#00", "3 or 8 hex digits"},
      {"(1700000000.123456) can0 800#00", "over 7FF"},
      {"(1700000000.123456) can0 40000000#00", "over 1FFFFFFF"},
      {"(1700000000.123456) can0 12G#00", "not hex"},
      {"(1700000000.123456) can0 123#0", "half a byte"},
      {"(1700000000.123456) can0 123#00.", "half a byte or a '.'"},
      {"(1700000000.123456) can0 123#001", "half a byte"},
      {"(1700000000.123456) can0 123#001122334455667788", "more than 8 data bytes"},
      {"(1700000000.123456) can0 123#R9", "DLC is one digit 0 to 8"},
      {"(1700000000.123456) can0 123##", "flags nibble"},
      {"(1700000000.123456) can0 123#zz", "not hex"},
  };
  for (const auto& [text, why] : bad) {
    const auto parsed = parse_candump_line(text);
    ASSERT_FALSE(parsed) << text;
    EXPECT_NE(parsed.error().text.find(why), std::string::npos) << text << ": " << parsed.error().text;
  }
  std::string fd_too_long = "(1.000000) can0 123##0";
  for (int i = 0; i < 65; ++i) fd_too_long += "00";
  const auto parsed = parse_candump_line(fd_too_long);
  ASSERT_FALSE(parsed);
  EXPECT_NE(parsed.error().text.find("more than 64 data bytes"), std::string::npos) << parsed.error().text;
}

TEST(CandumpLog, EveryWrittenLineParsesBackToItsFrame) {
  std::vector<CandumpFrame> frames = {classic_frame(0x000, {}), classic_frame(0x7FF, {1, 2, 3, 4, 5, 6, 7, 8}),
                                      classic_frame(0x1FFFFFFF | kCandumpEffFlag, {0xFF}),
                                      classic_frame(0x123 | kCandumpRtrFlag, {}),
                                      classic_frame(kCandumpErrFlag | 0x1FF, {1, 2, 3, 4, 5, 6, 7, 8})};
  for (std::uint8_t len : {0, 1, 8, 9, 12, 48, 64}) {
    CandumpFrame fd = classic_frame(0x1234 | kCandumpEffFlag, {});
    fd.fd = true;
    fd.flags = len % 16;
    fd.len = len;
    for (std::uint8_t i = 0; i < len; ++i) fd.data[i] = static_cast<std::uint8_t>(i * 7 + 1);
    frames.push_back(fd);
  }
  for (const CandumpFrame& frame : frames) {
    const std::string text = line_of(frame, "vcan0");
    const auto parsed = parse_candump_line(text);
    ASSERT_TRUE(parsed) << text << ": " << parsed.error().text;
    EXPECT_EQ(parsed.value().frame, frame) << text;
    EXPECT_EQ(parsed.value().utc_us, kTime / 1000);
    EXPECT_LE(text.size(), kCandumpMaxLine);
  }
}

}  // namespace
}  // namespace cosmic

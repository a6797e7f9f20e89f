// The log format of can-utils' `candump -l`, which `canplayer` replays (issue 37, docs/recording.md
// "CAN logs"): one line per frame,
//
//   (1700000000.123456) can0 123#DEADBEEF
//
// the frame's time (UTC seconds, a dot, six digits of microseconds; the seconds at least ten
// digits), the interface, and the frame as can-utils' lib.c writes it (sprint_canframe, no data
// separators): identifier in upper-case hex, 3 digits for a standard (11-bit) frame, 8 for an
// extended (29-bit) one; `#`; then
//   - classic data: the data bytes in hex (`123#` for none);
//   - remote request: `R`, followed by the DLC when it is not 0 (`123#R`, `123#R4`);
//   - CAN FD: a second `#`, the flags nibble (BRS 1, ESI 2), the data bytes (`123##1DEADBEEF`);
//   - error frame: 8 digits of the identifier with the error flag (0x20000000) and the error class
//     bits, then its data bytes like a classic frame (`20000004#0004000000000000`).
// Pure: no I/O, no state. Any thread.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "cosmic/result.hpp"

namespace cosmic {

// The identifier flags of SocketCAN's can_id (linux/can.h), so this unit needs no Linux header.
inline constexpr std::uint32_t kCandumpEffFlag = 0x80000000u;  // extended (29-bit) identifier
inline constexpr std::uint32_t kCandumpRtrFlag = 0x40000000u;  // remote request
inline constexpr std::uint32_t kCandumpErrFlag = 0x20000000u;  // error frame
inline constexpr std::uint32_t kCandumpSffMask = 0x000007FFu;
inline constexpr std::uint32_t kCandumpEffMask = 0x1FFFFFFFu;
inline constexpr std::size_t kCanMtu = 16;    // sizeof(struct can_frame)
inline constexpr std::size_t kCanFdMtu = 72;  // sizeof(struct canfd_frame)
// The longest line format_candump_line() writes for an interface of at most 15 characters.
inline constexpr std::size_t kCandumpMaxLine = 20 + 3 + 15 + 1 + 8 + 3 + 128 + 1;

// One frame as SocketCAN carries it.
struct CandumpFrame {
  std::uint32_t can_id = 0;             // identifier with kCandump*Flag bits, as struct can_frame's can_id
  bool fd = false;                      // CAN FD (a canfd_frame); never with the remote or error flag
  std::uint8_t flags = 0;               // CAN FD only: the flags nibble (BRS 0x01, ESI 0x02, ...)
  std::uint8_t len = 0;                 // data bytes (a remote request: its DLC), at most 8 classic, 64 FD
  std::array<std::uint8_t, 64> data{};  // the first `len` bytes count, the rest are zero
  friend bool operator==(const CandumpFrame&, const CandumpFrame&) = default;
};

// One line of a log.
struct CandumpLine {
  std::int64_t utc_us = 0;  // microseconds since the epoch
  std::string interface;    // 1 to 15 characters, no white space
  CandumpFrame frame;
  friend bool operator==(const CandumpLine&, const CandumpLine&) = default;
};

// A frame from the bytes of a `struct can_frame` (16 bytes) or `struct canfd_frame` (72 bytes) in
// this host's byte order; nullopt for any other length. A classic length over 8 is taken as 8 and
// an FD one over 64 as 64 (as candump prints them).
std::optional<CandumpFrame> candump_frame_from_wire(std::span<const std::uint8_t> bytes);
// The frame as the bytes of a can_frame or canfd_frame (what canplayer writes to the socket);
// returns the length used (kCanMtu or kCanFdMtu).
std::size_t candump_frame_to_wire(const CandumpFrame& frame, std::span<std::uint8_t, kCanFdMtu> out);

// `123#DEADBEEF` and the rest (above), appended to `out`.
void append_candump_frame(const CandumpFrame& frame, std::string& out);
// A whole line with its '\n', appended to `out`. A negative time is written as 0.
void append_candump_line(std::int64_t utc_ns, std::string_view interface, const CandumpFrame& frame, std::string& out);

// A line as candump -l writes it (a trailing '\n' or "\r\n" allowed, white space between the
// fields of any length); an error naming what is wrong otherwise. Accepted beyond what this unit
// writes, as canplayer does: lower-case hex and '.' between data bytes.
Result<CandumpLine> parse_candump_line(std::string_view line);
// The frame part alone (`123#DEADBEEF`).
Result<CandumpFrame> parse_candump_frame(std::string_view text);

}  // namespace cosmic

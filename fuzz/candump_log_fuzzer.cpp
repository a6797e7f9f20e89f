// A CAN log line as canplayer (and a later cosmicd replay) reads one (issue 37): any text through
// parse_candump_line, and any SocketCAN frame bytes through candump_frame_from_wire.
// Checked beyond "no crash": a line read is written again as candump -l writes it and reads back
// the same (time, interface, frame); what is written stays within kCandumpMaxLine; a frame from
// wire bytes round-trips through its line and through the bytes canplayer would write.
#include <array>
#include <cstdint>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "cosmic/candump_log.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

// The latest time the writer's nanoseconds can hold (the parser reads up to 12 digits of seconds).
constexpr std::int64_t kLatestUs = INT64_MAX / 1000;

void line_round_trip(const cosmic::CandumpLine& line) {
  if (line.utc_us > kLatestUs) return;
  std::string text;
  cosmic::append_candump_line(line.utc_us * 1000, line.interface, line.frame, text);
  require(text.size() <= cosmic::kCandumpMaxLine);
  const auto again = cosmic::parse_candump_line(text);
  require(again.ok());
  require(again.value() == line);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (const auto line = cosmic::parse_candump_line(text); line.ok()) {
    line_round_trip(line.value());
  } else {
    require(!line.error().text.empty());
  }
  // The same bytes as a can_frame or canfd_frame, as the CAN adapter's tap hands them over.
  for (const std::size_t mtu : {cosmic::kCanMtu, cosmic::kCanFdMtu}) {
    if (size < mtu) continue;
    const auto frame = cosmic::candump_frame_from_wire({data, mtu});
    require(frame.has_value());
    line_round_trip(cosmic::CandumpLine{1'700'000'000'000'000, "vcan0", *frame});
    std::array<std::uint8_t, cosmic::kCanFdMtu> wire{};
    require(cosmic::candump_frame_to_wire(*frame, wire) == mtu);
    require(cosmic::candump_frame_from_wire(std::span(wire).first(mtu)) == frame);
  }
  return 0;
}

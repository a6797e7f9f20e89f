// The fuzz loop the CAN wire formats share (fuzz/can_*_frames_fuzzer.cpp; can_frame_format.hpp).
// Input: [max event bytes: 2][FD: 1], then records:
//   [any byte, bit 7 clear][can_id: 4][length: 1][data]    a frame received (its sender: the identifier)
//   [0x80 | anything: 1][length: 2][event]                 an event encoded, then decoded again
// Invariants: a decoded event never exceeds the binding's maximum; an event the format encodes
// comes back whole from a receiver of its own (on CAN FD followed by nothing but padding zeros);
// partial events all time out.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "can_frame_format.hpp"
#include "fuzz_input.hpp"

namespace cosmic::fuzz {

struct CanFormatCase {
  can_detail::CanBus bus;
  std::size_t max_event = 1;
};

// Collects an event's frames.
class CollectFrames final : public can_detail::CanFrameBatchSink {
 public:
  bool take(std::span<const canfd_frame> frames) override {
    require(!frames.empty() && frames.size() <= can_detail::kFramesPerSubmit);
    out.insert(out.end(), frames.begin(), frames.end());
    return true;
  }
  std::vector<canfd_frame> out;
};

// `make(bus)` builds the format under test, `tx(format, max_event)` the binding it encodes for.
template <typename Make, typename Tx>
void fuzz_can_format(FuzzInput& in, const CanFormatCase& c, Make make, Tx tx) {
  auto format = make(c.bus);
  const can_detail::CanRxBinding rx{1, &format, 0x1234, c.max_event, format.fragments(c.max_event)};
  const bool carried = format.check_payload(c.max_event).ok();
  std::int64_t now = 0;
  while (!in.empty()) {
    const std::uint8_t op = in.byte();
    now += 100;
    if (op & 0x80) {
      const std::size_t length = (std::size_t{in.byte()} << 8 | in.byte()) % (c.max_event + 1);
      std::vector<std::uint8_t> event(length);
      const auto bytes = in.bytes(length);
      std::copy(bytes.begin(), bytes.end(), event.begin());
      if (!carried) continue;
      const can_detail::CanTxBinding binding = tx(format, c.max_event);
      CollectFrames frames;
      require(format.encode(binding, event, static_cast<std::uint8_t>(op & 0x0F), frames));
      require(frames.out.size() == format.frame_count(binding, event.size()));
      auto receiver = make(c.bus);
      std::optional<std::vector<std::uint8_t>> decoded;
      for (const canfd_frame& f : frames.out) {
        require(!decoded);  // only the last frame completes the event
        const auto r =
            receiver.decode(rx, f.can_id, std::span<const std::uint8_t>(f.data, f.len), c.bus.fd, Nanos(now));
        require(!r.lost && !r.displaced);
        if (r.event) decoded.emplace(r.event->begin(), r.event->end());
      }
      require(decoded && decoded->size() >= event.size() && decoded->size() <= c.max_event);
      require(std::equal(event.begin(), event.end(), decoded->begin()));
      require(std::all_of(decoded->begin() + static_cast<std::ptrdiff_t>(event.size()), decoded->end(),
                          [](std::uint8_t b) { return b == 0; }));
      continue;
    }
    const std::uint32_t can_id = (in.u32() & CAN_EFF_MASK) | CAN_EFF_FLAG;
    const auto data = in.bytes(in.byte() % (c.bus.fd ? 65 : 9));
    const auto r = format.decode(rx, can_id, data, c.bus.fd, Nanos(now));
    if (r.event) require(r.event->size() <= c.max_event);
  }
  format.expire(Nanos(now + 2'000'000'000), [](std::uint32_t) {});
  require(!format.next_deadline());
}

inline CanFormatCase read_can_format_case(FuzzInput& in, bool fd_allowed) {
  CanFormatCase c;
  c.max_event = (std::size_t{in.byte()} << 8 | in.byte()) + 1;
  c.bus.fd = fd_allowed && (in.byte() & 1);
  c.bus.brs = c.bus.fd;
  c.bus.capacity = c.bus.fd ? 64 : 8;
  return c;
}

}  // namespace cosmic::fuzz

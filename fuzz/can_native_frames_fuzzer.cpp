// Native CAN frames (a device's own identifier; the native format of can_frame_format.hpp): a
// received frame's contents against the channel's length, classic and FD, and events encoded and
// decoded again. Input: fuzz/can_format_fuzz.hpp.
#include <cstdint>

#include "can_format_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cosmic::can_detail;
  cosmic::fuzz::FuzzInput in(data, size);
  const auto c = cosmic::fuzz::read_can_format_case(in, true);
  cosmic::fuzz::fuzz_can_format(
      in, c, [](CanBus bus) { return NativeFrames(bus); },
      [](const CanFrameFormat& format, std::size_t max_event) {
        return CanTxBinding{1, &format, 0x3A0, 0x3A0, false, 0, max_event, false};
      });
  return 0;
}

// CAN frames in FAMOUSO's layout as the adapter receives them (the famouso format of
// can_frame_format.hpp: plain frames up to 8 bytes, AFP reassembly under the fragment flag), and
// events it encodes and decodes again; AFP headers. Input: fuzz/can_format_fuzz.hpp (classic CAN
// only: the FD byte is ignored).
#include <cstdint>

#include "can_format_fuzz.hpp"
#include "cosmic/can_wire.hpp"
#include "famouso_afp.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cosmic::can_detail;
  cosmic::fuzz::FuzzInput in(data, size);
  const auto c = cosmic::fuzz::read_can_format_case(in, false);
  cosmic::fuzz::fuzz_can_format(
      in, c,
      [](CanBus) {
        return FamousoFrames(CanReassemblyBounds{4, cosmic::Nanos(1000)});
      },
      [](const CanFrameFormat& format, std::size_t max_event) {
        const std::uint32_t id = 0x1E05123 & ~cosmic::kFamousoFragmentFlag;
        return CanTxBinding{1,    &format, id,        id | cosmic::kFamousoFragmentFlag,
                            true, 0x123,   max_event, format.fragments(max_event)};
      });
  cosmic::fuzz::FuzzInput headers(data, size);
  while (!headers.empty()) {
    const auto fragment = headers.bytes(1 + headers.byte() % 8);
    if (const auto header = cosmic::famouso::decode_afp_header(fragment)) {
      cosmic::fuzz::require(header->length <= fragment.size());
    }
  }
  return 0;
}

// CAN frames in this project's layout as the adapter receives them (the cosmic format of
// can_frame_format.hpp: single frames and NRT fragment reassembly, classic and FD), events it
// encodes and decodes again, the 29-bit identifier and the GET_ETAG / SUPPLY_ETAG binding frames.
// Input: fuzz/can_format_fuzz.hpp.
#include <algorithm>
#include <cstdint>

#include "can_binding.hpp"
#include "can_format_fuzz.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_wire.hpp"

using cosmic::fuzz::require;

namespace {

void check_binding_frame(std::uint32_t can_id, std::span<const std::uint8_t> data) {
  if (const auto request = cosmic::can_binding::decode_get_etag(can_id, data)) {
    require(data.size() == cosmic::can_binding::kFrameBytes);
    // A request carries the subject big-endian: encoding it again gives the same bytes.
    const auto again = cosmic::can_binding::get_etag_data(request->subject);
    require(std::equal(again.begin(), again.end(), data.begin()));
  }
  if (const auto supply = cosmic::can_binding::decode_supply_etag(data)) require(supply->part <= 1);
}

// The identifier, the fragment header and the binding frames of every received record.
void check_codecs(std::span<const std::uint8_t> input) {
  cosmic::fuzz::FuzzInput in(input.data(), input.size());
  in.bytes(3);
  while (!in.empty()) {
    if (in.byte() & 0x80) {
      in.bytes(std::size_t{in.byte()} << 8 | in.byte());
      continue;
    }
    const std::uint32_t can_id = in.u32() & 0x1FFFFFFF;
    const auto frame = in.bytes(in.byte() % 65);
    require(cosmic::encode_can_id(cosmic::decode_can_id(can_id)) == can_id);
    check_binding_frame(can_id, frame);
    if (frame.size() >= 2) {
      const auto value = static_cast<std::uint16_t>(frame[0] << 8 | frame[1]);
      require(cosmic::encode_fragment_header(cosmic::decode_fragment_header(value)) == value);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cosmic::can_detail;
  cosmic::fuzz::FuzzInput in(data, size);
  const auto c = cosmic::fuzz::read_can_format_case(in, true);
  cosmic::fuzz::fuzz_can_format(
      in, c,
      [](CanBus bus) {
        return CosmicFrames(bus, CanReassemblyBounds{4, cosmic::Nanos(1000)});
      },
      [](const CanFrameFormat& format, std::size_t max_event) {
        const std::uint32_t id = 0x0A05123;  // any identifier of the layout
        return CanTxBinding{1, &format, id, id, true, 0x123, max_event, format.fragments(max_event)};
      });
  check_codecs(std::span(data, size));
  return 0;
}

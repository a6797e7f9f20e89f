// CAN frames as the adapter receives them: the 29-bit identifier, fragment reassembly over a
// stream of frames from several sources (our fragment format and FAMOUSO's AFP), and the
// GET_ETAG / SUPPLY_ETAG binding frames.
// Input: [max event bytes: 2][FD: 1] then frames [source: 1][can_id: 4][length: 1][data].
#include <algorithm>
#include <cstdint>

#include "can_binding.hpp"
#include "famouso_afp.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_wire.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::FuzzInput;
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  const std::size_t max_event = (std::size_t{in.byte()} << 8 | in.byte()) + 1;
  const bool fd = in.byte() & 1;
  cosmic::ReassemblyLimits limits;
  limits.max_partials = 4;
  limits.timeout = cosmic::Nanos(1000);
  limits.padding_slack = fd ? 15 : 0;
  cosmic::Reassembler reassembler(limits);
  cosmic::famouso::AfpLimits afp_limits;
  afp_limits.max_partial_events = 4;
  afp_limits.idle_timeout = cosmic::Nanos(1000);
  cosmic::famouso::AfpReassembler afp(afp_limits);
  std::int64_t now = 0;
  while (!in.empty()) {
    const std::uint32_t source = in.byte() % 8;
    const std::uint32_t can_id = in.u32() & 0x1FFFFFFF;
    const auto frame = in.bytes(in.byte() % (fd ? 65 : 9));
    now += 100;

    const cosmic::CanIdentifier id = cosmic::decode_can_id(can_id);
    require(cosmic::encode_can_id(id) == can_id);
    check_binding_frame(can_id, frame);

    const auto result = reassembler.accept(source, frame, max_event, cosmic::Nanos(now));
    if (result.outcome == cosmic::FragmentOutcome::complete) require(result.event.size() <= max_event);
    require(reassembler.pending() <= limits.max_partials);

    if (const auto header = cosmic::famouso::decode_afp_header(frame)) require(header->length <= frame.size());
    const auto afp_result = afp.accept(source, frame, max_event, cosmic::Nanos(now));
    if (afp_result.outcome == cosmic::famouso::AfpOutcome::complete) require(afp_result.event.size() <= max_event);
    if (frame.size() >= 2) {
      const std::uint16_t value = static_cast<std::uint16_t>(frame[0] << 8 | frame[1]);
      require(cosmic::encode_fragment_header(cosmic::decode_fragment_header(value)) == value);
    }
  }
  reassembler.expire(cosmic::Nanos(now + 2000));
  require(reassembler.pending() == 0);
  return 0;
}

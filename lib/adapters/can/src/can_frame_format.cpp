#include "can_frame_format.hpp"

#include <algorithm>
#include <array>

#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"
#include "native_frames.hpp"

namespace cosmic::can_detail {
namespace {

constexpr std::size_t kFdPaddingSlack = 15;  // 48 -> 64 is the largest step between FD lengths

// A frame carrying no more than `len` data bytes of a bus: CAN FD pads to the next valid length.
std::uint8_t frame_length(std::size_t len, bool fd) {
  return static_cast<std::uint8_t>(fd ? fd_padded_length(static_cast<std::uint32_t>(len)) : len);
}

// The frames `next` writes (one per call, until `done`), kFramesPerSubmit at a time to `sink`.
template <typename Done, typename Next>
bool encode_in_batches(CanFrameBatchSink& sink, Done done, Next next) {
  std::array<canfd_frame, kFramesPerSubmit> batch{};
  while (!done()) {
    std::size_t count = 0;
    for (; count < batch.size() && !done(); ++count) {
      batch[count] = canfd_frame{};
      next(batch[count]);
    }
    if (!sink.take(std::span<const canfd_frame>(batch.data(), count))) return false;
  }
  return true;
}

// An event that is one frame's data (cosmic and FAMOUSO single frames): a device may send a
// shorter one; a CAN FD frame may carry padding up to the next FD length, cut off at the payload.
CanDecoded whole_frame(const CanRxBinding& binding, std::span<const std::uint8_t> data, bool fd_frame) {
  const std::size_t allowed =
      fd_frame ? fd_padded_length(static_cast<std::uint32_t>(binding.payload)) : binding.payload;
  if (data.size() > allowed) return CanDecoded{std::nullopt, true, std::nullopt};
  return CanDecoded{data.first(std::min(data.size(), binding.payload)), false, std::nullopt};
}

Result<void> within_fragments(std::uint64_t payload, std::uint32_t capacity) {
  if (!needs_fragmentation(payload, capacity) || payload <= max_fragmented_event(capacity)) return {};
  return Error{"payload " + std::to_string(payload) + " B exceeds " + std::to_string(max_fragmented_event(capacity)) +
               " B (" + std::to_string(kMaxFragments) + " fragments)"};
}

}  // namespace

std::uint32_t frame_source(canid_t can_id) {
  const CanIdentifier id = decode_can_id(can_id & CAN_EFF_MASK);
  return (static_cast<std::uint32_t>(id.tx_node) << 14) | id.etag;
}

// ------------------------------------------------------------------------------ cosmic

CosmicFrames::CosmicFrames(CanBus bus, CanReassemblyBounds bounds)
    : bus_(bus), reassembler_(ReassemblyLimits{bounds.max_partials, bounds.timeout, bus.fd ? kFdPaddingSlack : 0}) {}

Result<void> CosmicFrames::check_payload(std::uint64_t payload) const {
  return within_fragments(payload, bus_.capacity);
}

std::size_t CosmicFrames::frame_count(const CanTxBinding& binding, std::size_t bytes) const {
  return binding.fragmented ? fragment_count(bytes, bus_.capacity) : 1;
}

canfd_frame CosmicFrames::single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const {
  canfd_frame frame{};
  frame.can_id = binding.can_id | CAN_EFF_FLAG;
  frame.flags = bus_.fd && bus_.brs ? CANFD_BRS : 0;
  // copy_n, not memcpy: an empty event's bytes may be a null pointer.
  std::copy_n(payload.begin(), std::min(payload.size(), sizeof frame.data), frame.data);
  frame.len = frame_length(payload.size(), bus_.fd);
  return frame;
}

bool CosmicFrames::encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t sequence,
                          CanFrameBatchSink& sink) const {
  if (!binding.fragmented) {
    const canfd_frame frame = single_frame(binding, payload);
    return sink.take(std::span(&frame, 1));
  }
  Fragmenter fragments(payload, bus_.capacity, sequence);
  return encode_in_batches(
      sink, [&] { return fragments.done(); },
      [&](canfd_frame& frame) {
        frame.can_id = binding.fragment_id | CAN_EFF_FLAG;
        frame.flags = bus_.fd && bus_.brs ? CANFD_BRS : 0;
        frame.len = frame_length(fragments.next(std::span<std::uint8_t>(frame.data, bus_.capacity)), bus_.fd);
      });
}

CanDecoded CosmicFrames::decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data,
                                bool fd_frame, Nanos now) {
  if (!binding.fragmented) return whole_frame(binding, data, fd_frame);
  const FragmentResult r = reassembler_.accept(frame_source(can_id), data, binding.payload, now);
  CanDecoded decoded{std::nullopt, r.dropped_event || r.outcome == FragmentOutcome::rejected, r.displaced};
  if (r.outcome == FragmentOutcome::complete) decoded.event = r.event;
  return decoded;
}

void CosmicFrames::expire(Nanos now, const std::function<void(std::uint32_t)>& dropped) {
  reassembler_.expire(now, dropped);
}

// ------------------------------------------------------------------------------ FAMOUSO

FamousoFrames::FamousoFrames(CanReassemblyBounds bounds)
    : afp_(famouso::AfpLimits{bounds.max_partials, bounds.timeout}) {}

// Admission counts a FAMOUSO event's frames as section 6 does (at least AFP's), so the same bound.
Result<void> FamousoFrames::check_payload(std::uint64_t payload) const {
  return within_fragments(payload, famouso::kAfpMtu);
}

std::size_t FamousoFrames::frame_count(const CanTxBinding&, std::size_t bytes) const {
  return bytes > famouso::kAfpMtu ? famouso::afp_fragment_count(bytes) : 1;
}

canfd_frame FamousoFrames::single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const {
  canfd_frame frame{};
  frame.can_id = binding.can_id | CAN_EFF_FLAG;
  std::copy_n(payload.begin(), std::min(payload.size(), famouso::kAfpMtu), frame.data);
  frame.len = static_cast<std::uint8_t>(std::min(payload.size(), famouso::kAfpMtu));
  return frame;
}

bool FamousoFrames::encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t,
                           CanFrameBatchSink& sink) const {
  if (payload.size() <= famouso::kAfpMtu) {
    const canfd_frame frame = single_frame(binding, payload);
    return sink.take(std::span(&frame, 1));
  }
  famouso::AfpFragmenter fragments(payload);
  return encode_in_batches(
      sink, [&] { return fragments.done(); },
      [&](canfd_frame& frame) {
        frame.can_id = binding.fragment_id | CAN_EFF_FLAG;
        frame.len = static_cast<std::uint8_t>(fragments.next(std::span<std::uint8_t>(frame.data, famouso::kAfpMtu)));
      });
}

CanDecoded FamousoFrames::decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data,
                                 bool fd_frame, Nanos now) {
  if (!decode_famouso_id(can_id & CAN_EFF_MASK).fragment) return whole_frame(binding, data, fd_frame);
  const famouso::AfpResult r = afp_.accept(frame_source(can_id), data, binding.payload, now);
  CanDecoded decoded{std::nullopt, r.dropped_event || r.outcome == famouso::AfpOutcome::rejected, r.displaced};
  if (r.outcome == famouso::AfpOutcome::complete) decoded.event = r.event;
  return decoded;
}

void FamousoFrames::expire(Nanos now, const std::function<void(std::uint32_t)>& dropped) { afp_.expire(now, dropped); }

// ------------------------------------------------------------------------------ native

Result<void> NativeFrames::check_payload(std::uint64_t payload) const {
  if (payload <= bus_.capacity) return {};
  return Error{"payload " + std::to_string(payload) + " B does not fit one native frame (" +
               std::to_string(bus_.capacity) + " B)"};
}

canfd_frame NativeFrames::single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const {
  return can_native::encode(NativeCanFrame{binding.can_id, binding.extended}, payload, bus_.fd, bus_.brs);
}

bool NativeFrames::encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t,
                          CanFrameBatchSink& sink) const {
  const canfd_frame frame = single_frame(binding, payload);
  return sink.take(std::span(&frame, 1));
}

CanDecoded NativeFrames::decode(const CanRxBinding& binding, canid_t, std::span<const std::uint8_t> data, bool fd_frame,
                                Nanos) {
  const auto contents =
      can_native::contents(can_native::RxChannel{binding.id, binding.subject, binding.payload}, data, fd_frame);
  if (!contents) return CanDecoded{std::nullopt, true, std::nullopt};
  return CanDecoded{*contents, false, std::nullopt};
}

}  // namespace cosmic::can_detail

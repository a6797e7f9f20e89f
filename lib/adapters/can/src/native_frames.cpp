#include "native_frames.hpp"

#include <algorithm>
#include <cstring>

#include "cosmic/can_timing.hpp"

namespace cosmic::can_native {

canid_t socket_id(const NativeCanFrame& frame) {
  return frame.extended ? (frame.can_id & CAN_EFF_MASK) | CAN_EFF_FLAG : frame.can_id & CAN_SFF_MASK;
}

bool FrameTable::add_publisher(const NativeCanFrame& frame, const RxChannel& channel) {
  return rx_.emplace(socket_id(frame), channel).second;
}

void FrameTable::add_subscriber(const NativeCanFrame& frame) { sent_.insert(socket_id(frame)); }

void FrameTable::add_background(const CanBackgroundFrame& frame) {
  background_.insert(socket_id(NativeCanFrame{frame.can_id, frame.extended}));
}

const RxChannel* FrameTable::find(canid_t can_id) const {
  if (can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) return nullptr;  // remote requests carry no event
  const auto it = rx_.find(can_id);
  return it == rx_.end() ? nullptr : &it->second;
}

bool FrameTable::is_background(canid_t can_id) const { return background_.count(can_id & ~CAN_RTR_FLAG) != 0; }

bool FrameTable::explains(canid_t can_id) const {
  const canid_t id = can_id & ~CAN_RTR_FLAG;
  return rx_.count(id) != 0 || sent_.count(id) != 0 || background_.count(id) != 0;
}

std::vector<can_filter> FrameTable::filters() const {
  std::vector<can_filter> out;
  out.reserve(rx_.size());
  for (const auto& [id, channel] : rx_) {
    // The identifier, its format and "not a remote request" all have to match.
    const canid_t mask = ((id & CAN_EFF_FLAG) ? CAN_EFF_MASK : CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    out.push_back(can_filter{id, mask});
  }
  return out;
}

std::optional<std::span<const std::uint8_t>> contents(const RxChannel& channel, std::span<const std::uint8_t> data,
                                                      bool fd_frame) {
  const std::size_t allowed =
      fd_frame ? fd_padded_length(static_cast<std::uint32_t>(channel.payload)) : channel.payload;
  if (data.size() > allowed) return std::nullopt;
  return data.first(std::min(data.size(), channel.payload));
}

canfd_frame encode(const NativeCanFrame& frame, std::span<const std::uint8_t> payload, bool fd, bool brs) {
  canfd_frame out{};
  out.can_id = socket_id(frame);
  // copy_n, not memcpy: an empty event's bytes may be a null pointer (found by fuzz_can_native_frames).
  std::copy_n(payload.begin(), std::min(payload.size(), sizeof out.data), out.data);
  const auto len = static_cast<std::uint32_t>(payload.size());
  out.len = static_cast<std::uint8_t>(fd ? fd_padded_length(len) : len);
  out.flags = fd && brs ? CANFD_BRS : 0;
  return out;
}

}  // namespace cosmic::can_native

// The native CAN wire format (ChannelSpec::native, docs/can-wire-format.md "Native frames"): a
// channel is one identifier that the devices on the bus already use, standard or extended; a
// frame's data bytes are one event's contents. No etag, no envelope, no fragmentation.
//
// Also the bus's declared background frames (CanSegmentProperties::background): frames that are
// not the gateway's but are explained, so the receive path neither delivers them nor counts them as
// unknown. Plain values built by configure(), read by the receive thread through the adapter's
// table snapshot (never changed after it is published).
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "cosmic/event.hpp"
#include "cosmic/model.hpp"

namespace cosmic::can_detail {
class SecocRx;
}

namespace cosmic::can_native {

// The identifier as the socket reports it: CAN_EFF_FLAG set for an extended identifier.
canid_t socket_id(const NativeCanFrame& frame);

struct RxChannel {
  ChannelId id = kNoChannel;
  std::uint64_t subject = 0;
  std::size_t payload = 0;                       // the channel's largest event
  std::shared_ptr<can_detail::SecocRx> secoc{};  // the hop's SecOC, if any
};

class FrameTable {
 public:
  // False when the identifier is already a channel's (one sender per identifier).
  bool add_publisher(const NativeCanFrame& frame, const RxChannel& channel);
  void add_subscriber(const NativeCanFrame& frame);  // the gateway sends it
  void add_background(const CanBackgroundFrame& frame);

  // The channel of a received data frame's identifier (can_id as read, flags included).
  const RxChannel* find(canid_t can_id) const;
  // True for a declared background frame's identifier.
  bool is_background(canid_t can_id) const;
  // True for any identifier of this table: a native channel's (either role) or a background frame's.
  bool explains(canid_t can_id) const;
  // Exact-match kernel filters for the native channels bound as publisher (data frames only).
  std::vector<can_filter> filters() const;
  std::size_t size() const { return rx_.size(); }

 private:
  std::unordered_map<canid_t, RxChannel> rx_;
  std::unordered_set<canid_t> background_;
  std::unordered_set<canid_t> sent_;  // native channels bound as subscriber
};

// A received frame's contents for `channel`: its data bytes, cut at the channel's payload where
// a CAN FD frame carries padding up to the next FD length; nullopt for a frame longer than the
// channel allows (a decode error).
std::optional<std::span<const std::uint8_t>> contents(const RxChannel& channel, std::span<const std::uint8_t> data,
                                                      bool fd_frame);

// The frame carrying `payload` as native frame `frame` (the caller checked it fits one frame).
// `fd`: a CAN FD bus (data padded to the next FD length, `brs` sets bit-rate switching).
canfd_frame encode(const NativeCanFrame& frame, std::span<const std::uint8_t> payload, bool fd, bool brs);

}  // namespace cosmic::can_native

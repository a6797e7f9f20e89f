// One channel bound on an LCM segment, as the adapter's table holds it (lcm_adapter.cpp) and its
// transmit side reads it (lcm_transmit.hpp).
#pragma once

#include <cstdint>
#include <string>

#include <memory>

#include "cosmic/model.hpp"
#include "lcm_message_format.hpp"

namespace cosmic::lcm_detail {

// rx: the gateway receives it here (HopRole::publisher); tx: the gateway sends it here
// (HopRole::subscriber). Both may be set.
struct Channel {
  ChannelId id = kNoChannel;
  std::string name;  // the LCM channel name, 1-63 bytes
  std::uint64_t subject = 0;
  std::shared_ptr<const LcmMessageFormat> format;  // envelope or raw: how its messages read and write
  ChannelClass cls = ChannelClass::nrt;            // which transmit socket sends it
  bool rx = false;
  bool tx = false;
};

}  // namespace cosmic::lcm_detail

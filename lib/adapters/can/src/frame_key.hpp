// A SocketCAN frame's place in bus arbitration (cosmic/can_timing.hpp's arbitration_key, from
// the identifier and its format flag): lower wins. Pure.
#pragma once

#include <linux/can.h>

#include <cstdint>

#include "cosmic/can_timing.hpp"

namespace cosmic {

inline std::uint32_t frame_arbitration_key(canid_t can_id) {
  const bool extended = (can_id & CAN_EFF_FLAG) != 0;
  return arbitration_key(can_id & (extended ? CAN_EFF_MASK : CAN_SFF_MASK),
                         extended ? CanIdFormat::extended29 : CanIdFormat::standard11);
}

}  // namespace cosmic

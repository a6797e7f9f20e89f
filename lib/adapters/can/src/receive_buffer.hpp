// How large the CAN adapter's receive socket buffer must be. Pure.
//
// The kernel drops a frame when the socket's queued memory passes its buffer (counted by
// SO_RXQ_OVFL). With Linux's default (net.core.rmem_default, 208 KiB) and 768 bytes of kernel
// memory per queued CAN frame (measured: an skb per frame, classic or FD, kernel 6.1), a socket
// holds 277 frames: a burst on a 1 Mbit/s bus fills that in 13 ms, less than a time-shared
// receive thread may wait for a CPU on a busy machine, while the kernel's cangw, which forwards
// in the kernel's receive path, loses nothing. So the buffer is sized for the bus itself
// (cosmic/can_buffering.hpp): every frame the bus can carry during kCanHold, whatever is bound
// now, so that a rebinding never needs a new socket.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "cosmic/can_buffering.hpp"
#include "cosmic/model.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

// How long the receive thread may be held off its CPU without losing a frame.
inline constexpr Nanos kReceiveHold = kCanHold;
// Kernel memory one queued frame costs (skb truesize, measured on Debian's 6.1 kernel).
inline constexpr std::size_t kKernelBytesPerFrame = 768;
// Never less than Linux's default buffer holds.
inline constexpr std::size_t kMinReceiveFrames = 256;

// Frames the receive socket must hold: the bus's frame rate at its shortest frame times kReceiveHold.
inline std::size_t receive_buffer_frames(const CanSegmentProperties& can) {
  return std::max(kMinReceiveFrames, can_frames_within(can, kReceiveHold));
}

// The value to hand SO_RCVBUF(FORCE): the kernel doubles it for its bookkeeping and counts each
// frame's truesize against the doubled value.
inline int receive_buffer_request(std::size_t frames) {
  const std::size_t bytes = frames * kKernelBytesPerFrame / 2;
  return static_cast<int>(std::min<std::size_t>(bytes, 1u << 30));
}

// Frames a buffer of `granted` bytes (SO_RCVBUF as getsockopt reports it: doubled) holds.
inline std::size_t frames_held(int granted) {
  return granted <= 0 ? 0 : static_cast<std::size_t>(granted) / kKernelBytesPerFrame;
}

}  // namespace cosmic

// A socket's receive buffer, as large as this process may make it. Linux only.
//
// SO_RCVBUFFORCE where the process may (CAP_NET_ADMIN), else SO_RCVBUF, which the kernel caps at
// net.core.rmem_max; an error of both leaves the kernel's default. What the socket got is read
// back, for the caller to judge in its own units (CAN frames, LCM bytes) and to warn once.
//
// Threads: whoever opens the socket (an adapter's control thread); no state of its own.
#pragma once

namespace cosmic {

struct ReceiveBufferSize {
  int requested = 0;  // what SO_RCVBUF was asked for, in bytes
  // SO_RCVBUF as getsockopt reports it: twice what was set, as Linux counts its bookkeeping in
  // the buffer too. 0 when it could not be read.
  int reported = 0;
  // The bytes of data the buffer was asked to hold that it holds (reported / 2).
  int usable() const noexcept { return reported / 2; }
  bool short_of_request() const noexcept { return usable() < requested; }
};

// Asks for a receive buffer of `bytes` (clamped to INT_MAX / 2) on socket `fd`.
ReceiveBufferSize size_receive_buffer(int fd, long long bytes);

}  // namespace cosmic

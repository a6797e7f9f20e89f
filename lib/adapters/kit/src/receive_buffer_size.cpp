#include "cosmic/receive_buffer_size.hpp"

#include <sys/socket.h>

#include <algorithm>
#include <climits>

namespace cosmic {

ReceiveBufferSize size_receive_buffer(int fd, long long bytes) {
  ReceiveBufferSize out;
  out.requested = static_cast<int>(std::clamp<long long>(bytes, 0, INT_MAX / 2));
  if (::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &out.requested, sizeof out.requested) != 0) {
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &out.requested, sizeof out.requested);  // an error leaves the default
  }
  socklen_t length = sizeof out.reported;
  if (::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &out.reported, &length) != 0) out.reported = 0;
  return out;
}

}  // namespace cosmic

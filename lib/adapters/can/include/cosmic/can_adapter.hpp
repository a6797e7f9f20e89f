// The CAN segment adapter on Linux SocketCAN (CAN_RAW, classic and FD, 29-bit identifiers in the
// COSMIC layout; docs/can-wire-format.md). One receive thread per segment owns the socket: it
// reads frames, reassembles fragmented events, answers GET_ETAG binding requests, drains the
// send backlog and watches the interface (down, missing, bus-off), reopening the socket when the
// interface comes back so traffic resumes by itself.
#pragma once

#include <memory>
#include <string>

#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/wire_tap.hpp"

namespace cosmic {

namespace can_detail {
class SecocFreshness;
}
// The SecOC freshness counters of one CAN segment's channels (docs/security.md), persisted in
// `file` across restarts. One per segment for the life of the process: the adapters that attach
// the segment in turn (a reload that replaces the adapter) share it, so no counter is used twice.
using CanSecocState = std::shared_ptr<can_detail::SecocFreshness>;
CanSecocState make_can_secoc_state(std::string file, const std::string& segment, Logger& log);

struct CanAdapterOptions {
  // Null: the adapter keeps its own, not persisted (tests), and senders are not held to a lease.
  CanSecocState secoc;
  // Null: none. Otherwise handed every frame the adapter reads from its socket (its bound channels'
  // and the binding protocols' frames, error frames) and every frame it writes, as the bytes of a
  // struct can_frame or canfd_frame (cosmic/wire_tap.hpp), from the threads that read and write.
  std::shared_ptr<WireTap> tap;
};

// Never null. start() succeeds even when the interface is down or missing (health says so).
std::unique_ptr<SegmentAdapter> make_can_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log,
                                                 CanAdapterOptions options = {});

}  // namespace cosmic

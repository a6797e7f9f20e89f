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

namespace cosmic {

struct CanAdapterOptions {
  // Where the SecOC freshness counters of the segment's channels persist across restarts
  // (docs/security.md); empty: not persisted (tests), and senders are not held to a lease.
  std::string secoc_state_file;
};

// Never null. start() succeeds even when the interface is down or missing (health says so).
std::unique_ptr<SegmentAdapter> make_can_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log,
                                                 CanAdapterOptions options = {});

}  // namespace cosmic

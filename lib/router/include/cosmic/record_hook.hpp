// Where the router hands events to a recorder (issue 37, docs/recording.md): each admitted event of
// a channel the recording selects, at the moment it leaves ingress for the lanes (where a tap sees
// it), with the segment it came from. A typed channel's event is in the compact layout.
//
// Threads: offer() runs on the ingress threads of every segment, concurrently, on the forwarding
// path: it must never block, allocate or do I/O (the recorder copies the event into its own bounded
// queue, or counts it dropped). Whoever sets the hook (Router::set_record_hook) keeps it alive as
// long as the router's inboxes can receive.
#pragma once

#include <cstddef>
#include <span>

#include "cosmic/event.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

class RecordHook {
 public:
  virtual ~RecordHook() = default;
  virtual void offer(ChannelId channel, std::size_t from_segment, const EventHeader& header, Nanos received_at,
                     std::span<const std::uint8_t> payload) noexcept = 0;
};

}  // namespace cosmic

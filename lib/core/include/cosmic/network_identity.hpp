// Which network a segment attaches, as every gateway attached to it names it (federation,
// docs/federation.md). Pure.
#pragma once

#include <string>

#include "cosmic/model.hpp"

namespace cosmic {

// The identity of the network a segment attaches, equal on every gateway attached to it:
//   dds: "dds:domain=N" (plus ";server=IP:PORT" with a discovery server)
//   lcm: "lcm:GROUP:PORT" (memq:// is process-local: empty)
//   can: "can:NAME" from the segment's `network` key (interface names are local: without the key
//        the bus is taken to be this gateway's alone, empty)
// A `network` key on an IP segment overrides the derived identity ("dds:NAME", "lcm:NAME").
std::string network_identity(const SegmentSpec& segment);

}  // namespace cosmic

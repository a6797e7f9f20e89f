// Builds the adapter of a segment by its type. The only place that knows every transport.
#pragma once

#include <string>

#include "cosmic/gateway.hpp"

namespace cosmicd {

// `state_directory`: where adapters keep what must survive a restart (a CAN segment's SecOC
// freshness counters: secoc-SEGMENT.json).
std::unique_ptr<cosmic::SegmentAdapter> make_adapter(const cosmic::SegmentSpec& segment,
                                                     const cosmic::GatewayIdentity& self, cosmic::Logger& log,
                                                     const std::string& state_directory);

}  // namespace cosmicd

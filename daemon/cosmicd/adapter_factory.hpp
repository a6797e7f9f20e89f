// Builds the adapter of a segment by its type. The only place that knows every transport.
#pragma once

#include "cosmic/gateway.hpp"

namespace cosmicd {

std::unique_ptr<cosmic::SegmentAdapter> make_adapter(const cosmic::SegmentSpec& segment,
                                                     const cosmic::GatewayIdentity& self, cosmic::Logger& log);

}  // namespace cosmicd

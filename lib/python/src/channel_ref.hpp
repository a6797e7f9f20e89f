// cosmic.Channel as Python holds it: the channel and a reference to its client, which keeps the
// C client open while any of its channels is still referenced.
#pragma once

#include <memory>

#include "binding.hpp"

namespace cosmic::python {

struct ChannelRef {
  std::shared_ptr<ClientState> client;
  ChannelState* channel = nullptr;  // owned by client
};

}  // namespace cosmic::python

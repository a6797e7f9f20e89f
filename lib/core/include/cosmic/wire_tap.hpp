// A generic look at what an adapter puts on and takes off its network, unit by unit (issue 37: CAN
// logs in candump -l format). An adapter that offers it is given a WireTap when it is made (its
// factory's options, e.g. cosmic::CanAdapterOptions::tap) and hands the tap every wire unit it
// receives and every one it sends, as the transport has it: for SocketCAN one `struct can_frame`
// (16 bytes) or `struct canfd_frame` (72 bytes). The tap knows nothing of the adapter, the adapter
// nothing of what the tap does with the unit; adapters that offer no tap simply take none.
//
// Ownership: the adapter holds the tap (shared) for its life and calls it until stop() returns.
// Threads: on_wire() is called on the adapter's receive threads and on the egress lanes that send
// (several at once); it must never block, allocate or do I/O: copy the unit into a bounded queue
// or count it dropped.
#pragma once

#include <cstdint>
#include <span>

#include "cosmic/units.hpp"

namespace cosmic {

enum class WireDirection : std::uint8_t { received, sent };

struct WireUnit {
  WireDirection direction = WireDirection::received;
  Nanos steady{0};                      // when, on the forwarding path's clock (cosmic/steady_clock.hpp)
  std::int64_t utc_ns = 0;              // when, on CLOCK_REALTIME: the kernel's receive stamp where there is one
  std::span<const std::uint8_t> bytes;  // valid during the call only
};

class WireTap {
 public:
  virtual ~WireTap() = default;
  virtual void on_wire(const WireUnit& unit) noexcept = 0;
};

}  // namespace cosmic

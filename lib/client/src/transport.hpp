// How libcosmic-client reaches one segment. Internal. The C API (client.cpp) owns one Transport
// per cosmic_client; a Transport calls Delivery from its receive thread(s).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "cosmic/event.hpp"
#include "cosmic/model.hpp"

namespace cosmic::client_detail {

class Delivery {
 public:
  // An event of the channel announced as `index`, on a receive thread of the transport.
  virtual void deliver(std::size_t index, const EventHeader& header, std::span<const std::uint8_t> payload) = 0;

 protected:
  ~Delivery() = default;
};

class Transport {
 public:
  virtual ~Transport() = default;
  // Opens the network; events go to `delivery`, which outlives the transport. COSMIC_* code.
  virtual int start(Delivery& delivery, std::string& error) = 0;
  // Adds channel `index` (0, 1, 2, ... in announce order) with the component's roles.
  virtual int announce(std::size_t index, const ChannelSpec& spec, int roles, int timeout_ms, std::string& error) = 0;
  // One event of channel `index`, announced with COSMIC_PUBLISH. Never throws.
  virtual int send(std::size_t index, const EventHeader& header, std::span<const std::uint8_t> payload,
                   std::string& error) = 0;
  // Remote endpoints matched with the component's endpoint of `role` on channel `index`
  // (COSMIC_PUBLISH: readers of its writer; COSMIC_SUBSCRIBE: writers of its reader), never
  // counting the component's own; nullopt where the transport has no discovery to ask (LCM, CAN).
  // Any thread; cheap enough to poll every millisecond.
  virtual std::optional<std::size_t> matched(std::size_t index, int role) const = 0;
};

// "dds:..." and "lcm:..." through the gateway's own segment adapters, roles mirrored: the
// component's publication is the adapter's sending side.
std::unique_ptr<Transport> make_ip_transport(const SegmentSpec& segment);
// "can:IFACE?node=N" on SocketCAN.
std::unique_ptr<Transport> make_can_transport(const std::string& interface, std::uint8_t node);

}  // namespace cosmic::client_detail

// The control protocol's taps (`cosmicctl echo`; docs/control-protocol.md, "echo"): echo_open,
// echo_read and echo_close over the gateway's taps (cosmic/channel_tap.hpp), with each event's
// contents decoded for a typed channel (JSON, as the JSON representation writes it) and in hex for
// an untyped one. A tap nobody reads for kIdleTap is closed, so a client that went away without
// echo_close leaves nothing running. Control thread only.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "cosmic/gateway.hpp"
#include "cosmic/json_representation.hpp"

namespace cosmic::control_detail {

class EchoTaps {
 public:
  using Json = nlohmann::json;
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kIdleTap{10};

  explicit EchoTaps(Gateway& gateway) : gateway_(gateway) {}
  ~EchoTaps();
  EchoTaps(const EchoTaps&) = delete;
  EchoTaps& operator=(const EchoTaps&) = delete;

  Json open(const Json& request, Clock::time_point now);
  Json read(const Json& request, Clock::time_point now);
  Json close(const Json& request);
  // Closes the taps nobody read for kIdleTap (called on every request).
  void expire(Clock::time_point now);

 private:
  struct Open {
    std::string channel;
    std::unique_ptr<JsonRepresentation> json;  // typed channels only
    Clock::time_point last_read;
  };
  Json event_json(const Open& tap, const TappedEvent& event) const;
  std::map<std::uint32_t, Open> open_;
  Gateway& gateway_;
};

}  // namespace cosmic::control_detail

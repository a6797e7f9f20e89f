// The metrics endpoint's `listen` value, HOST:PORT (config_loader.cpp's gateway.metrics). Internal
// to cosmic_config; pure, any thread.
#pragma once

#include <cstdint>
#include <string>

namespace cosmic::config_detail {

struct ListenAddress {
  std::string host;
  std::uint16_t port = 0;
  bool loopback = false;
  std::string error;  // why the text is not HOST:PORT
};

// "127.0.0.1:9877", "[::1]:9877" or "localhost:9877": an IP literal (never a name to resolve,
// so what is checked is what gets bound) and a port.
ListenAddress parse_listen_address(const std::string& text);

}  // namespace cosmic::config_detail

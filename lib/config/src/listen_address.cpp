#include "listen_address.hpp"

#include <arpa/inet.h>

#include <charconv>
#include <utility>

namespace cosmic::config_detail {
namespace {

ListenAddress invalid_listen(std::string why) {
  ListenAddress out;
  out.error = std::move(why);
  return out;
}

}  // namespace

ListenAddress parse_listen_address(const std::string& text) {
  ListenAddress out;
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return invalid_listen("has no port");
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value == 0 || value > 65535) {
    return invalid_listen("has no port from 1 to 65535");
  }
  out.port = static_cast<std::uint16_t>(value);
  const bool bracketed = host.size() >= 2 && host.front() == '[' && host.back() == ']';
  if (bracketed) host = host.substr(1, host.size() - 2);
  if (host == "localhost") host = "127.0.0.1";
  in_addr v4{};
  in6_addr v6{};
  if (!bracketed && inet_pton(AF_INET, host.c_str(), &v4) == 1) {
    out.loopback = (ntohl(v4.s_addr) >> 24) == 127;
  } else if (bracketed && inet_pton(AF_INET6, host.c_str(), &v6) == 1) {
    out.loopback = IN6_IS_ADDR_LOOPBACK(&v6);
  } else {
    return invalid_listen("has no IP address as host (IPv6 goes in brackets)");
  }
  out.host = host;
  return out;
}

}  // namespace cosmic::config_detail

#include "cosmic/lcm_url.hpp"

#include "cosmic/escaped_text.hpp"

#include <charconv>

namespace cosmic {
namespace {

constexpr std::string_view kUdpm = "udpm://";
constexpr std::string_view kMemq = "memq://";
constexpr std::string_view kLcmDefaultGroup = "239.255.76.67";

// The URL as an error message shows it (escaped_text.hpp), at most 80 characters.
std::string shown(std::string_view text) { return escaped_text(text, 80); }

// A decimal number in [min, max] spelled with digits only (no sign, no base prefix, no spaces).
std::optional<unsigned> decimal(std::string_view text, unsigned min, unsigned max) {
  if (text.empty() || text.size() > 10) return std::nullopt;
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value, 10);
  if (ec != std::errc() || end != text.data() + text.size() || value < min || value > max) return std::nullopt;
  return value;
}

// Dotted-decimal IPv4 in 224.0.0.0/4.
bool multicast_group(std::string_view text) {
  unsigned octets[4];
  for (int i = 0; i < 4; ++i) {
    const std::size_t dot = i < 3 ? text.find('.') : text.size();
    if (dot == std::string_view::npos) return false;
    const auto value = decimal(text.substr(0, dot), 0, 255);
    if (!value || (dot > 1 && text[0] == '0')) return false;  // no leading zeros (octal in inet_aton)
    octets[i] = *value;
    text.remove_prefix(i < 3 ? dot + 1 : dot);
  }
  return octets[0] >= 224 && octets[0] <= 239;
}

}  // namespace

Result<LcmUrl> parse_lcm_url(std::string_view url) {
  const std::string hint = "'" + shown(url) + "': ";
  if (url == kMemq) return LcmUrl{true, "", 0, std::nullopt, std::nullopt};
  if (url.substr(0, kUdpm.size()) != kUdpm)
    return Error{hint + "only udpm://GROUP:PORT?ttl=N and memq:// are supported"};
  std::string_view rest = url.substr(kUdpm.size());
  const std::size_t query = rest.find('?');
  std::string_view network = rest.substr(0, query);
  std::string_view options = query == std::string_view::npos ? std::string_view() : rest.substr(query + 1);
  LcmUrl out;
  const std::size_t colon = network.find(':');
  if (colon != std::string_view::npos) {
    const auto port = decimal(network.substr(colon + 1), 1, 65535);
    if (!port) return Error{hint + "the port must be a decimal number 1..65535 and end the address"};
    out.port = static_cast<std::uint16_t>(*port);
    network = network.substr(0, colon);
  }
  if (network.empty() && colon == std::string_view::npos) network = kLcmDefaultGroup;  // LCM's default
  if (!multicast_group(network))
    return Error{hint + "the group must be an IPv4 multicast address (224.0.0.0 to 239.255.255.255)"};
  out.group = std::string(network);
  while (query != std::string_view::npos && !options.empty()) {
    const std::size_t amp = options.find('&');
    const std::string_view option = options.substr(0, amp);
    options = amp == std::string_view::npos ? std::string_view() : options.substr(amp + 1);
    const std::size_t eq = option.find('=');
    const std::string_view name = option.substr(0, eq);
    const std::string_view value = eq == std::string_view::npos ? std::string_view() : option.substr(eq + 1);
    if (name == "ttl") {
      out.ttl = decimal(value, 0, 255);
      if (!out.ttl) return Error{hint + "ttl must be a decimal number 0..255"};
    } else if (name == "recv_buf_size") {
      out.recv_buf_size = decimal(value, 1, 1u << 30);
      if (!out.recv_buf_size) return Error{hint + "recv_buf_size must be a decimal number of bytes (at most 1 GiB)"};
    } else {
      return Error{hint + "unknown option '" + shown(name) + "' (ttl and recv_buf_size are supported)"};
    }
  }
  if (query != std::string_view::npos && rest.back() == '&') return Error{hint + "empty option after '&'"};
  return out;
}

}  // namespace cosmic

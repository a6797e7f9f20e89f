#include "cosmic/secoc.hpp"

#include <array>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

namespace cosmic {
namespace {

constexpr std::uint64_t kSecocMaxFreshness = std::numeric_limits<std::uint64_t>::max();
constexpr unsigned kSecocMaxWindow = 16;

void secoc_put_be(std::uint64_t value, std::span<std::uint8_t> out) noexcept {
  for (std::size_t i = out.size(); i-- > 0; value >>= 8) out[i] = static_cast<std::uint8_t>(value & 0xFF);
}

std::uint64_t secoc_get_be(std::span<const std::uint8_t> in) noexcept {
  std::uint64_t value = 0;
  for (const std::uint8_t byte : in) value = (value << 8) | byte;
  return value;
}

// The CMAC of data ID || data || freshness (all big-endian) in `mac`.
bool secoc_mac(MessageAuth& auth, std::uint32_t data_id, std::span<const std::uint8_t> data, std::uint64_t freshness,
               MacBytes& mac) noexcept {
  std::array<std::uint8_t, 4> id{};
  std::array<std::uint8_t, 8> fresh{};
  secoc_put_be(data_id, id);
  secoc_put_be(freshness, fresh);
  return auth.compute({std::span<const std::uint8_t>(id), data, std::span<const std::uint8_t>(fresh)}, mac);
}

Result<MessageAuth> secoc_auth(std::span<const std::uint8_t> key, const SecocParameters& parameters) {
  if (Result<void> checked = check_secoc_parameters(parameters); !checked) return std::move(checked).error();
  if (key.size() != kSecocKeyBytes)
    return Error{"a SecOC key has 16 bytes (AES-128), this one " + std::to_string(key.size())};
  Result<MessageAuth> auth = MessageAuth::make(MacAlgorithm::aes128_cmac, key);
  if (!auth) return Error{"SecOC: " + auth.error().text};
  return auth;
}

}  // namespace

Result<void> check_secoc_parameters(const SecocParameters& p) {
  if (p.mac_bits < 8 || p.mac_bits > 128 || p.mac_bits % 8 != 0)
    return Error{"SecOC mac_bits " + std::to_string(p.mac_bits) + " is not valid: 8 to 128, a multiple of 8"};
  if (p.freshness_bits > 64 || p.freshness_bits % 8 != 0)
    return Error{"SecOC freshness_bits " + std::to_string(p.freshness_bits) +
                 " is not valid: 0 to 64, a multiple of 8"};
  if (p.freshness_window < 1 || p.freshness_window > kSecocMaxWindow)
    return Error{"SecOC freshness_window " + std::to_string(p.freshness_window) + " is not valid: 1 to " +
                 std::to_string(kSecocMaxWindow)};
  return {};
}

const char* to_string(SecocStatus status) noexcept {
  switch (status) {
    case SecocStatus::authentic:
      return "authentic";
    case SecocStatus::replayed:
      return "replayed";
    case SecocStatus::unauthenticated:
      break;
  }
  return "unauthenticated";
}

// ---- sender

SecocSender::SecocSender(MessageAuth auth, const SecocParameters& parameters, std::uint64_t freshness) noexcept
    : auth_(std::move(auth)), parameters_(parameters), freshness_(freshness) {}

Result<SecocSender> SecocSender::make(std::span<const std::uint8_t> key, const SecocParameters& parameters,
                                      std::uint64_t freshness) {
  Result<MessageAuth> auth = secoc_auth(key, parameters);
  if (!auth) return std::move(auth).error();
  return SecocSender(std::move(auth).value(), parameters, freshness);
}

std::size_t SecocSender::protect(std::span<const std::uint8_t> data, std::span<std::uint8_t> out) noexcept {
  const std::size_t fresh_bytes = parameters_.freshness_bits / 8;
  const std::size_t mac_bytes = parameters_.mac_bits / 8;
  const std::size_t size = data.size() + fresh_bytes + mac_bytes;
  if (out.size() < size || freshness_ == kSecocMaxFreshness) return 0;
  const std::uint64_t next = freshness_ + 1;
  MacBytes mac{};
  // The MAC first: `out` may overlap `data`.
  if (!secoc_mac(auth_, parameters_.data_id, data, next, mac)) return 0;
  if (!data.empty() && out.data() != data.data()) std::memmove(out.data(), data.data(), data.size());
  secoc_put_be(next, out.subspan(data.size(), fresh_bytes));  // the low freshness_bits
  std::memcpy(out.data() + data.size() + fresh_bytes, mac.data(), mac_bytes);
  freshness_ = next;
  return size;
}

// ---- receiver

SecocReceiver::SecocReceiver(MessageAuth auth, const SecocParameters& parameters, std::uint64_t freshness) noexcept
    : auth_(std::move(auth)), parameters_(parameters), freshness_(freshness) {}

Result<SecocReceiver> SecocReceiver::make(std::span<const std::uint8_t> key, const SecocParameters& parameters,
                                          std::uint64_t freshness) {
  Result<MessageAuth> auth = secoc_auth(key, parameters);
  if (!auth) return std::move(auth).error();
  return SecocReceiver(std::move(auth).value(), parameters, freshness);
}

bool SecocReceiver::mac_matches(std::span<const std::uint8_t> data, std::span<const std::uint8_t> mac,
                                std::uint64_t fresh) noexcept {
  MacBytes computed{};
  if (!secoc_mac(auth_, parameters_.data_id, data, fresh, computed)) return false;
  return tags_equal(std::span<const std::uint8_t>(computed), mac, mac.size());
}

SecocReading SecocReceiver::verify(std::span<const std::uint8_t> secured) noexcept {
  const unsigned bits = parameters_.freshness_bits;
  const std::size_t fresh_bytes = bits / 8;
  const std::size_t overhead = overhead_bytes();
  if (secured.size() < overhead) return SecocReading{};
  const std::size_t data_size = secured.size() - overhead;
  const auto data = secured.first(data_size);
  const auto received = secoc_get_be(secured.subspan(data_size, fresh_bytes));
  const auto mac = secured.subspan(data_size + fresh_bytes);
  const std::uint64_t last = freshness_;

  const auto authentic = [&](std::uint64_t fresh) noexcept {
    freshness_ = fresh;
    return SecocReading{SecocStatus::authentic, data_size, fresh};
  };
  const auto replayed = [&](std::uint64_t fresh) noexcept {
    return SecocReading{SecocStatus::replayed, data_size, fresh};
  };

  if (bits == 0) {
    // Nothing in the frame: the next few values, then the last few for a replay.
    const std::uint64_t window = parameters_.freshness_window;
    for (std::uint64_t step = 1; step <= window && step <= kSecocMaxFreshness - last; ++step)
      if (mac_matches(data, mac, last + step)) return authentic(last + step);
    for (std::uint64_t step = 0; step < window && step <= last; ++step)
      if (mac_matches(data, mac, last - step)) return replayed(last - step);
    return SecocReading{};
  }

  if (bits == 64) {
    if (received > last) return mac_matches(data, mac, received) ? authentic(received) : SecocReading{};
    return mac_matches(data, mac, received) ? replayed(received) : SecocReading{};
  }

  // Truncated: the value in last's epoch, and the next one or the previous one.
  const std::uint64_t epoch = std::uint64_t{1} << bits;
  const std::uint64_t mask = epoch - 1;
  const std::uint64_t same_epoch = (last & ~mask) | received;
  std::optional<std::uint64_t> fresh;  // > last
  std::optional<std::uint64_t> stale;  // <= last
  if (same_epoch > last) {
    fresh = same_epoch;
    if (same_epoch >= epoch) stale = same_epoch - epoch;
  } else {
    if (same_epoch <= kSecocMaxFreshness - epoch) fresh = same_epoch + epoch;  // never past UINT64_MAX
    stale = same_epoch;
  }
  if (fresh && mac_matches(data, mac, *fresh)) return authentic(*fresh);
  if (stale && mac_matches(data, mac, *stale)) return replayed(*stale);
  return SecocReading{};
}

}  // namespace cosmic

#include "cosmic/lcm_auth.hpp"

#include <algorithm>
#include <limits>

namespace cosmic {
namespace {

constexpr std::size_t kSignedTrailerBytes = kLcmAuthTrailerSize - kLcmAuthTagSize;  // sender, sequence, sent_ns

void put_be64(std::uint8_t* p, std::uint64_t v) noexcept {
  for (std::size_t i = 8; i-- > 0;) {
    p[i] = static_cast<std::uint8_t>(v);
    v >>= 8;
  }
}

std::uint64_t get_be64(const std::uint8_t* p) noexcept {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8; ++i) v = v << 8 | p[i];
  return v;
}

// The tag's input, in parts: channel name length and name, the message's parts, the trailer's head.
constexpr std::size_t kMaxMessageParts = 4;

bool lcm_auth_tag(MessageAuth& mac, std::string_view channel, std::span<const std::span<const std::uint8_t>> message,
                  std::span<const std::uint8_t> head, MacBytes& out) noexcept {
  if (channel.size() > 255 || message.size() > kMaxMessageParts) return false;
  const std::uint8_t length = static_cast<std::uint8_t>(channel.size());
  std::array<std::span<const std::uint8_t>, kMaxMessageParts + 3> parts{};
  std::size_t n = 0;
  parts[n++] = std::span(&length, 1);
  parts[n++] = std::span(reinterpret_cast<const std::uint8_t*>(channel.data()), channel.size());
  for (const auto& part : message) parts[n++] = part;
  parts[n++] = head;
  return mac.compute(std::span(parts.data(), n), out);
}

}  // namespace

const char* to_string(LcmAuthVerdict verdict) {
  switch (verdict) {
    case LcmAuthVerdict::authentic:
      return "authentic";
    case LcmAuthVerdict::unauthenticated:
      return "unauthenticated";
    case LcmAuthVerdict::replayed:
      return "replayed";
  }
  return "?";
}

Result<LcmAuthSigner> LcmAuthSigner::make(std::span<const std::uint8_t> key, std::uint64_t sender) {
  Result<MessageAuth> mac = MessageAuth::make(MacAlgorithm::hmac_sha256, key);
  if (!mac) return std::move(mac).error();
  return LcmAuthSigner(std::move(mac).value(), sender);
}

bool LcmAuthSigner::sign(std::string_view channel, std::span<const std::span<const std::uint8_t>> parts,
                         std::int64_t sent_ns, LcmAuthTrailer& trailer) noexcept {
  put_be64(trailer.data(), sender_);
  put_be64(trailer.data() + 8, sequence_ + 1);
  put_be64(trailer.data() + 16, static_cast<std::uint64_t>(sent_ns));
  MacBytes tag{};
  if (!lcm_auth_tag(mac_, channel, parts, std::span(trailer.data(), kSignedTrailerBytes), tag)) return false;
  std::copy_n(tag.begin(), kLcmAuthTagSize, trailer.begin() + kSignedTrailerBytes);
  ++sequence_;
  return true;
}

LcmAuthVerifier::LcmAuthVerifier(std::vector<MessageAuth> macs, Nanos window)
    : macs_(std::move(macs)), window_ns_(window.count()) {
  senders_.reserve(kMaxSenders);
}

Result<LcmAuthVerifier> LcmAuthVerifier::make(std::span<const std::uint8_t> key, Nanos window) {
  const std::span<const std::uint8_t> keys[] = {key};
  return make(keys, window);
}

Result<LcmAuthVerifier> LcmAuthVerifier::make(std::span<const std::span<const std::uint8_t>> keys, Nanos window) {
  if (window <= Nanos::zero()) return Error{"the replay window must be longer than 0"};
  if (keys.empty()) return Error{"no key to check tags with"};
  std::vector<MessageAuth> macs;
  for (const auto& key : keys) {
    Result<MessageAuth> mac = MessageAuth::make(MacAlgorithm::hmac_sha256, key);
    if (!mac) return std::move(mac).error();
    macs.push_back(std::move(mac).value());
  }
  return LcmAuthVerifier(std::move(macs), window);
}

bool LcmAuthVerifier::authentic_tag(std::string_view channel, std::span<const std::uint8_t> body,
                                    const std::uint8_t* trailer) noexcept {
  const std::span<const std::uint8_t> tag(trailer + kSignedTrailerBytes, kLcmAuthTagSize);
  for (MessageAuth& mac : macs_) {
    MacBytes computed{};
    if (lcm_auth_tag(mac, channel, std::span(&body, 1), std::span(trailer, kSignedTrailerBytes), computed) &&
        tags_equal(computed, tag, kLcmAuthTagSize))
      return true;
  }
  return false;
}

LcmAuthCheck LcmAuthVerifier::check(std::string_view channel, std::span<const std::uint8_t> message,
                                    std::int64_t now_ns) noexcept {
  LcmAuthCheck out;
  if (message.size() < kLcmAuthTrailerSize) return out;
  const std::size_t size = message.size() - kLcmAuthTrailerSize;
  const std::uint8_t* trailer = message.data() + size;
  out.sender = get_be64(trailer);
  if (!authentic_tag(channel, message.first(size), trailer)) return out;
  const auto sent_ns = static_cast<std::int64_t>(get_be64(trailer + 16));
  // A key holder chooses sent_ns freely: the difference saturates instead of overflowing.
  if (__builtin_sub_overflow(sent_ns, now_ns, &out.skew_ns))
    out.skew_ns = sent_ns < 0 ? std::numeric_limits<std::int64_t>::min() : std::numeric_limits<std::int64_t>::max();
  out.verdict = LcmAuthVerdict::replayed;
  // Outside the window either way: recorded long ago, or from a clock too far ahead.
  if (out.skew_ns < -window_ns_ || out.skew_ns > window_ns_) return out;
  // Senders expire against the latest clock reading: a clock stepped back must not make an expired
  // sender's old messages look fresh to a forgotten window.
  latest_now_ns_ = std::max(latest_now_ns_, now_ns);
  Sender* sender = find_or_add(out.sender);
  if (sender == nullptr) {
    out.crowded = true;
    return out;
  }
  if (!sender->window.accept(get_be64(trailer + 8))) return out;
  sender->last_sent_ns = std::max(sender->last_sent_ns, sent_ns);
  out.verdict = LcmAuthVerdict::authentic;
  out.message_size = size;
  return out;
}

LcmAuthVerifier::Sender* LcmAuthVerifier::find_or_add(std::uint64_t id) noexcept {
  // Whatever a sender sent before latest - window is refused by its time alone: once its newest
  // message is that old, its window may go (another sender's entry, or a fresh one for itself, so
  // that a number pushed up by another holder of the key does not silence it for good).
  const std::int64_t horizon = latest_now_ns_ - window_ns_;
  Sender* expired = nullptr;
  for (Sender& s : senders_) {
    if (s.id == id) {
      if (s.last_sent_ns < horizon) s = Sender{id, horizon, {}};
      return &s;
    }
    if (expired == nullptr && s.last_sent_ns < horizon) expired = &s;
  }
  if (expired == nullptr) {
    if (senders_.size() == kMaxSenders) return nullptr;
    expired = &senders_.emplace_back();  // within the reserved capacity: no allocation
  }
  *expired = Sender{id, horizon, {}};
  return expired;
}

}  // namespace cosmic

// Authenticated LCM (issue 36, item 3): LCM has no security of its own, so on a segment with
// `auth: {key_file, window}` every message cosmicd sends carries a trailer after its envelope, and
// every message it receives must carry a valid one. docs/lcm-mapping.md ("Authentication") is the
// wire format's reference; docs/security.md what it protects.
//
// The trailer, 40 bytes after the LCM message (the envelope), big-endian:
//    0  uint64  sender     a random number per transmit socket and start: whose sequence it is
//    8  uint64  sequence   per sender, from 1
//   16  int64   sent_ns    the sender's wall clock when it signed (nanoseconds since the epoch)
//   24  16 B    tag        HMAC-SHA256, its first 16 bytes, over: the LCM channel name's length
//                          (1 byte) and name, the message, and the trailer's first 24 bytes
// The channel name is inside the tag, so a message moved to another channel is not authentic.
// Receivers that know nothing of the trailer (lcm-gen's decoders in lcm-spy, lcm-logger) read
// the envelope before it and ignore the bytes after.
//
// A receiver takes a message when its tag is valid (else: unauthenticated), its sent_ns lies within
// `window` of the receiver's clock (else: replayed; so a recorded datagram is refused once the
// window has passed, even by a receiver that restarted since), and its sender's sequence number was
// not taken before (ReplayWindow; else: replayed). Senders are forgotten once their last
// datagram is older than the window (against the latest clock reading seen); at most kMaxSenders
// are remembered at a time. Every holder of the key is trusted alike: one can also write under
// another's sender number and so make that sender's next messages (for up to one window after its
// last) count as replayed; give writers that must not interfere with each other different keys.
//
// Threads: a signer belongs to one transmit socket (its class's mutex), a verifier to the segment's
// receive thread. sign()/check() never throw; no allocation but OpenSSL's own (message_auth.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "cosmic/lcm_auth_layout.hpp"
#include "cosmic/message_auth.hpp"
#include "cosmic/replay_window.hpp"
#include "cosmic/result.hpp"
#include "cosmic/units.hpp"

namespace cosmic {

using LcmAuthTrailer = std::array<std::uint8_t, kLcmAuthTrailerSize>;

class LcmAuthSigner {
 public:
  // `sender`: a random number, new with every start (getrandom), so a restarted sender's numbers
  // from 1 are a new sender's and not replays.
  static Result<LcmAuthSigner> make(std::span<const std::uint8_t> key, std::uint64_t sender);

  // The trailer of the message made of `parts` on LCM channel `channel` (at most 255 bytes),
  // signed at `sent_ns`; takes the next sequence number. False when the MAC fails (nothing is
  // taken then and the message must not be sent).
  bool sign(std::string_view channel, std::span<const std::span<const std::uint8_t>> parts, std::int64_t sent_ns,
            LcmAuthTrailer& trailer) noexcept;

  std::uint64_t sender() const noexcept { return sender_; }
  std::uint64_t last_sequence() const noexcept { return sequence_; }

 private:
  LcmAuthSigner(MessageAuth mac, std::uint64_t sender) : mac_(std::move(mac)), sender_(sender) {}
  MessageAuth mac_;
  std::uint64_t sender_;
  std::uint64_t sequence_ = 0;
};

enum class LcmAuthVerdict : std::uint8_t { authentic, unauthenticated, replayed };
const char* to_string(LcmAuthVerdict verdict);

struct LcmAuthCheck {
  LcmAuthVerdict verdict = LcmAuthVerdict::unauthenticated;
  std::size_t message_size = 0;  // the bytes before the trailer (authentic only)
  std::uint64_t sender = 0;      // the trailer's sender (0 when the message is too short for one)
  std::int64_t skew_ns = 0;      // sent_ns less the receiver's clock, saturated (authentic tag only)
  bool crowded = false;          // replayed because kMaxSenders other senders are active in the window
};

class LcmAuthVerifier {
 public:
  static constexpr std::size_t kMaxSenders = 256;

  static Result<LcmAuthVerifier> make(std::span<const std::uint8_t> key, Nanos window);
  // Tags made with any of `keys` count (a key change: the new key accepted before it signs, the old
  // one still accepted while senders change over); the first is tried first.
  static Result<LcmAuthVerifier> make(std::span<const std::span<const std::uint8_t>> keys, Nanos window);

  // One received message of LCM channel `channel`, trailer included, at the receiver's wall clock
  // `now_ns`. Only an authentic message moves its sender's window.
  LcmAuthCheck check(std::string_view channel, std::span<const std::uint8_t> message, std::int64_t now_ns) noexcept;

 private:
  struct Sender {
    std::uint64_t id = 0;
    std::int64_t last_sent_ns = 0;  // of its newest authentic message
    ReplayWindow window;
  };
  LcmAuthVerifier(std::vector<MessageAuth> macs, Nanos window);
  bool authentic_tag(std::string_view channel, std::span<const std::uint8_t> body,
                     const std::uint8_t* trailer) noexcept;
  // The sender's entry (emptied when it expired), a new one in place of one that expired; null when
  // all are in use.
  Sender* find_or_add(std::uint64_t id) noexcept;

  std::vector<MessageAuth> macs_;  // one per accepted key, never empty
  std::int64_t window_ns_;
  std::int64_t latest_now_ns_ = std::numeric_limits<std::int64_t>::min() / 2;  // the latest clock reading
  std::vector<Sender> senders_;  // kMaxSenders reserved by make(): never grows past them
};

}  // namespace cosmic

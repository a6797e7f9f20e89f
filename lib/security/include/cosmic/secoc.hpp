// SecOC on CAN (issue 36, item 4): the shape of AUTOSAR Secure Onboard Communication's secured
// I-PDU, so that a frame says it comes from a holder of the key, carries exactly the data that was
// sent, and is not an old frame sent again. A hop's `secoc: {key_file, mac_bits, freshness_bits}`
// protects the frames the gateway sends and checks the ones it receives.
//
// The secured PDU, byte for byte:
//
//     authentic data || truncated freshness value || truncated MAC
//
//   - truncated freshness value: the low freshness_bits of the 64-bit freshness counter,
//     big-endian, freshness_bits/8 bytes (none with freshness_bits == 0);
//   - truncated MAC: the first mac_bits/8 bytes of the AES-128-CMAC (NIST SP 800-38B, RFC 4493)
//     over the MAC input
//
//     data ID (4 bytes big-endian) || authentic data || complete freshness value (8 bytes big-endian)
//
//   overhead_bytes() = (freshness_bits + mac_bits) / 8 follow the authentic data. The data ID binds
//   a frame to its stream (the caller chooses it: the CAN identifier, or the channel's id); it is
//   32 bits, where AUTOSAR's SecOCDataId has 16, so that a 29-bit identifier fits whole.
//
// The sender counts: each protect() uses the next freshness value (last used + 1). The counter
// starts from the value the caller restored (the last one used before a restart, persisted with
// freshness()) and never wraps: once UINT64_MAX has been used, protect() refuses.
//
// The receiver reconstructs the complete freshness value from the truncated one as AUTOSAR does,
// relative to the last value it accepted ("last"), with mask = 2^freshness_bits - 1:
//     candidate = (last & ~mask) | received;  if candidate <= last: candidate += 2^freshness_bits
// (the truncated value ran over into the next epoch). It then checks the MAC with the candidate:
//   - it matches: authentic, and last = candidate;
//   - else, if the MAC matches the value one epoch earlier (candidate - 2^freshness_bits, which
//     is <= last): replayed, a frame that was authentic once and is sent again;
//   - else unauthenticated (forged, damaged, another key or data ID, or from too far away).
// Hence up to 2^freshness_bits - 1 frames in a row may be lost and the next still counts; more,
// and the receiver cannot tell the epoch (the sender and receiver must then resynchronize, e.g.
// by restoring the receiver's last value). A replay more than one epoch old reads as
// unauthenticated, which is refused all the same.
//   - freshness_bits == 64: the received value is the candidate; a value <= last whose MAC
//     matches is replayed.
//   - freshness_bits == 0 (nothing in the frame): the receiver tries last+1 .. last+N with
//     N = freshness_window, so N-1 lost frames in a row are tolerated; a frame authentic for one
//     of last-N+1 .. last is replayed. An unauthenticated frame costs 2N CMACs.
// No candidate beyond UINT64_MAX is ever tried: a receiver whose last value is UINT64_MAX accepts
// nothing more. A frame shorter than the overhead is unauthenticated. Only an authentic frame
// moves `last`; a refused one leaves the receiver as it was.
//
// The caller gives verify() the exact secured PDU: where CAN FD rounds a frame up to its DLC's
// length, the padding must be cut off first (the channel knows its payload's size).
//
// Pure: no I/O, no allocation after make() (MessageAuth's CMAC allocates none). Threads: an
// instance is used by one thread at a time (its counter and its MAC context are mutable state);
// make() may be called from any thread. Everything after make() is noexcept and returns values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "cosmic/message_auth.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

struct SecocParameters {
  std::uint32_t data_id = 0;      // first in the MAC input, big-endian
  unsigned mac_bits = 24;         // 8 to 128, a multiple of 8 (24: AUTOSAR's profile 1)
  unsigned freshness_bits = 8;    // 0 to 64, a multiple of 8 (8: AUTOSAR's profile 1)
  unsigned freshness_window = 4;  // 1 to 16; only with freshness_bits == 0 (see above)
  friend bool operator==(const SecocParameters&, const SecocParameters&) = default;
};

inline constexpr std::size_t kSecocKeyBytes = 16;  // AES-128

// Ok, or what is wrong with `parameters`: the value and its valid range.
Result<void> check_secoc_parameters(const SecocParameters& parameters);

// (freshness_bits + mac_bits) / 8: what a secured PDU carries beyond the authentic data.
constexpr std::size_t secoc_overhead_bytes(const SecocParameters& parameters) noexcept {
  return (parameters.freshness_bits + parameters.mac_bits) / 8;
}

class SecocSender {
 public:
  // A sender keyed with `key` (16 bytes; SecretKey::bytes()) whose last used freshness value is
  // `freshness` (the first frame carries freshness + 1); else why not.
  static Result<SecocSender> make(std::span<const std::uint8_t> key, const SecocParameters& parameters,
                                  std::uint64_t freshness);

  const SecocParameters& parameters() const noexcept { return parameters_; }
  std::size_t overhead_bytes() const noexcept { return secoc_overhead_bytes(parameters_); }
  // The last freshness value used (the one to persist), or the starting value before any frame.
  std::uint64_t freshness() const noexcept { return freshness_; }

  // Writes the secured PDU of `data` with the next freshness value into `out` and returns its size
  // (data.size() + overhead_bytes()); 0, with the counter unchanged, when `out` is too small, the
  // counter is at UINT64_MAX or the MAC cannot be computed. `out` may begin at `data` (protecting
  // in place, with room for the overhead behind the data).
  std::size_t protect(std::span<const std::uint8_t> data, std::span<std::uint8_t> out) noexcept;

 private:
  SecocSender(MessageAuth auth, const SecocParameters& parameters, std::uint64_t freshness) noexcept;

  MessageAuth auth_;
  SecocParameters parameters_;
  std::uint64_t freshness_;
};

enum class SecocStatus : std::uint8_t { authentic, unauthenticated, replayed };
const char* to_string(SecocStatus status) noexcept;

// What verify() found in one secured PDU.
struct SecocReading {
  SecocStatus status = SecocStatus::unauthenticated;
  std::size_t authentic_size = 0;  // the authentic data: the PDU's first bytes (authentic or replayed), else 0
  std::uint64_t freshness = 0;     // the complete freshness value (authentic or replayed), else 0
};

class SecocReceiver {
 public:
  // A receiver keyed with `key` (16 bytes) whose last accepted freshness value is `freshness`
  // (the caller restores it, or starts from the sender's starting value); else why not.
  static Result<SecocReceiver> make(std::span<const std::uint8_t> key, const SecocParameters& parameters,
                                    std::uint64_t freshness);

  const SecocParameters& parameters() const noexcept { return parameters_; }
  std::size_t overhead_bytes() const noexcept { return secoc_overhead_bytes(parameters_); }
  // The last accepted freshness value (the one to persist).
  std::uint64_t freshness() const noexcept { return freshness_; }

  // Checks one secured PDU (exactly as sent, see above); on `authentic` the freshness value moves.
  SecocReading verify(std::span<const std::uint8_t> secured) noexcept;

 private:
  SecocReceiver(MessageAuth auth, const SecocParameters& parameters, std::uint64_t freshness) noexcept;

  // Whether the PDU's truncated MAC is that of the authentic data with freshness value `fresh`.
  bool mac_matches(std::span<const std::uint8_t> data, std::span<const std::uint8_t> mac, std::uint64_t fresh) noexcept;

  MessageAuth auth_;
  SecocParameters parameters_;
  std::uint64_t freshness_;
};

}  // namespace cosmic

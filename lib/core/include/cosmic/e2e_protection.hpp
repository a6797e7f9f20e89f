// End-to-end protection of a DBC message's frame (issue 35; `type: {dbc: FILE, message: NAME,
// e2e: {counter: SIG, crc: SIG, data_id: N}}`): an alive counter that says how many frames went
// missing or came twice, and a CRC over the frame and a data ID that says the frame is intact and
// is the message it claims to be. The shape of AUTOSAR E2E profile 1 (docs/typed-layout.md,
// "End-to-end protection", says which configurations are exactly profile 1):
//   - CRC-8 SAE J1850 (polynomial 0x1D) as profile 1 runs it: start value 0x00, no final XOR, over
//     the data ID's bytes (both: low then high; low: the low byte; alt: the low byte with an even
//     counter, the high byte with an odd one), then every byte of the frame but the CRC's own;
//   - a 4-bit counter runs 0..14 (15 is invalid); a counter of 2..16 other bits runs 0..2^n-1.
// The counter and CRC signals are protection, not contents: the channel's type leaves them out
// (e2e_payload_message), the gateway checks them on frames it receives and writes them on frames it
// sends.
//
// Pure: no I/O, no allocation after make(); check()/protect() run on the forwarding threads, any
// number at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "cosmic/dbc.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// Which bytes of the data ID the CRC covers (profile 1's DataIDMode; the nibble mode, which also
// sends part of the ID in the frame, is not offered).
enum class E2eDataIdMode : std::uint8_t { both, low, alt };
const char* to_string(E2eDataIdMode mode);

// What the configuration says: the names of the counter and CRC signals of the message, the data
// ID, and where the key stood (for errors).
struct E2eSpec {
  std::string counter;
  std::string crc;
  std::uint16_t data_id = 0;
  E2eDataIdMode data_id_mode = E2eDataIdMode::both;
  friend bool operator==(const E2eSpec&, const E2eSpec&) = default;
};

// CRC-8 with polynomial 0x1D (SAE J1850), not reflected, over `bytes` from register `start`,
// without a final XOR: the standard's check value is crc8_j1850(data, 0xFF) ^ 0xFF, profile 1's CRC
// is crc8_j1850(data, 0x00). Chains: crc8_j1850(b, crc8_j1850(a, s)) is the CRC of a then b.
std::uint8_t crc8_j1850(std::span<const std::uint8_t> bytes, std::uint8_t start) noexcept;

// What the check of one received frame found.
struct E2eReading {
  bool intact = false;        // the CRC matches and the counter is a valid value
  std::uint32_t counter = 0;  // the counter's value (meaningful when intact)
};

class E2eProtection {
 public:
  // The protection of `message` by `spec`; else why not: a signal that does not exist or is
  // multiplexed, a CRC that is not one whole byte, a counter that is not an unsigned integer of 2 to
  // 16 bits or overlaps the CRC, a message with no byte left to protect.
  static Result<E2eProtection> make(const DbcMessage& message, const E2eSpec& spec);

  // How many values the counter runs through before it wraps (15 for 4 bits, else 2^bits).
  std::uint32_t counter_modulus() const noexcept { return modulus_; }
  std::size_t frame_length() const noexcept { return length_; }

  // A received frame's data (at least frame_length() bytes; CAN FD padding beyond is ignored).
  E2eReading check(std::span<const std::uint8_t> frame) const noexcept;
  // Writes `counter` (reduced modulo counter_modulus()) and then the CRC into a frame whose other
  // signals are packed (at least frame_length() bytes).
  void protect(std::span<std::uint8_t> frame, std::uint64_t counter) const noexcept;
  // The CRC the frame should carry when its counter is `counter`.
  std::uint8_t crc_of(std::span<const std::uint8_t> frame, std::uint32_t counter) const noexcept;

 private:
  E2eProtection(DbcSignal counter, std::size_t crc_byte, std::size_t length, E2eSpec spec);

  DbcSignal counter_;
  std::size_t crc_byte_ = 0;
  std::size_t length_ = 0;
  std::uint32_t modulus_ = 0;
  E2eSpec spec_;
};

// The message as its channel's type sees it: without the counter and CRC signals of `spec`.
DbcMessage e2e_payload_message(const DbcMessage& message, const E2eSpec& spec);

// A receiver's view of the counter: how many frames between the previous one it received and this
// one never came (omitted), or whether this one is the previous one again (repeated). Without a
// previous frame (the first after start) nothing is judged. A gap of a whole modulus or more, or a
// frame older than the previous one, cannot be told from a shorter gap (the counter wraps): it
// counts as the gap it looks like.
struct E2eStep {
  bool repeated = false;
  std::uint32_t omitted = 0;
};
E2eStep e2e_step(std::optional<std::uint32_t> previous, std::uint32_t counter, std::uint32_t modulus) noexcept;

}  // namespace cosmic

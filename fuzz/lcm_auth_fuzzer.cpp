// An authenticated LCM segment's check of every received message (cosmic/lcm_auth.hpp), the
// receive thread's first look at bytes from the network. Two receivers see each input: one takes it
// as it came (a forgery: it must never be authentic, since the fuzzer does not hold the key), the
// other takes the rest of it signed by a holder of the key, with a trailer made here from the
// documented layout (docs/lcm-mapping.md) whose signing time, sequence number and flipped byte
// the input's first 17 bytes choose: authentic exactly when the time lies within the window and
// the number is not 0, then replayed the second time, and unauthenticated with that byte flipped.
#include <cstdint>
#include <cstring>
#include <vector>

#include "cosmic/lcm_auth.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

constexpr std::int64_t kNow = 1'790'000'000'000'000'000;
constexpr std::int64_t kWindowNs = 1'000'000'000;

std::vector<std::uint8_t> lcm_auth_fuzz_key() {
  std::vector<std::uint8_t> key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(0xA5 ^ (i * 29));
  return key;
}

std::uint64_t lcm_auth_fuzz_be64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = v << 8 | p[i];
  return v;
}

// The message `body` with a trailer by the documented layout: sender, sequence, sent_ns, then the
// first 16 bytes of HMAC-SHA256 over name length, name, message and those 24 bytes.
std::vector<std::uint8_t> lcm_auth_fuzz_signed(std::span<const std::uint8_t> body, std::uint64_t sequence,
                                               std::int64_t sent_ns) {
  std::vector<std::uint8_t> head(24);
  const std::uint64_t fields[] = {0x5eed, sequence, static_cast<std::uint64_t>(sent_ns)};
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < 8; ++i) head[f * 8 + i] = static_cast<std::uint8_t>(fields[f] >> (56 - 8 * i));
  auto mac = cosmic::MessageAuth::make(cosmic::MacAlgorithm::hmac_sha256, lcm_auth_fuzz_key()).value();
  const std::uint8_t length = 8;
  cosmic::MacBytes tag{};
  require(mac.compute({std::span(&length, 1), std::span(reinterpret_cast<const std::uint8_t*>("obstacle"), 8), body,
                       std::span<const std::uint8_t>(head)},
                      tag));
  std::vector<std::uint8_t> wire(body.begin(), body.end());
  wire.insert(wire.end(), head.begin(), head.end());
  wire.insert(wire.end(), tag.begin(), tag.begin() + 16);
  return wire;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace std::chrono_literals;
  const auto key = lcm_auth_fuzz_key();

  auto forged = cosmic::LcmAuthVerifier::make(key, 1s).value();
  const cosmic::LcmAuthCheck as_sent = forged.check("obstacle", std::span(data, size), kNow);
  require(as_sent.verdict != cosmic::LcmAuthVerdict::authentic);
  require(as_sent.message_size == 0);

  if (size < 17) return 0;
  const auto sent_ns = static_cast<std::int64_t>(lcm_auth_fuzz_be64(data));
  const std::uint64_t sequence = lcm_auth_fuzz_be64(data + 8);
  const std::uint8_t flip = data[16];
  const std::span<const std::uint8_t> body(data + 17, size - 17);
  std::vector<std::uint8_t> wire = lcm_auth_fuzz_signed(body, sequence, sent_ns);

  auto verifier = cosmic::LcmAuthVerifier::make(key, 1s).value();
  const cosmic::LcmAuthCheck checked = verifier.check("obstacle", wire, kNow);
  // Within the window, without an overflow: sent_ns - kNow in [-window, window].
  const bool in_window = sent_ns >= kNow - kWindowNs && sent_ns <= kNow + kWindowNs;
  const bool fresh = in_window && sequence != 0;
  require(checked.verdict ==
          (fresh ? cosmic::LcmAuthVerdict::authentic : cosmic::LcmAuthVerdict::replayed));  // the tag is valid
  if (fresh) {
    require(checked.message_size == body.size());
    require(verifier.check("obstacle", wire, kNow).verdict == cosmic::LcmAuthVerdict::replayed);
  }
  wire[flip % wire.size()] ^= static_cast<std::uint8_t>(1u << (flip % 8));
  auto fresh_verifier = cosmic::LcmAuthVerifier::make(key, 1s).value();
  require(fresh_verifier.check("obstacle", wire, kNow).verdict == cosmic::LcmAuthVerdict::unauthenticated);
  return 0;
}

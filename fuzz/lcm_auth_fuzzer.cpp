// An authenticated LCM segment's check of every received message (cosmic/lcm_auth.hpp), the
// receive thread's first look at bytes from the network. Two receivers see each input: one takes it
// as it came (a forgery: it must never be authentic, since the fuzzer does not hold the key), the
// other takes it signed by a holder of the key (it must be authentic exactly once, with its bytes
// before the trailer, and never again; any flipped byte of it must not be authentic).
#include <cstdint>
#include <vector>

#include "cosmic/lcm_auth.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

constexpr std::int64_t kNow = 1'790'000'000'000'000'000;

std::vector<std::uint8_t> lcm_auth_fuzz_key() {
  std::vector<std::uint8_t> key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(0xA5 ^ (i * 29));
  return key;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace std::chrono_literals;
  const auto key = lcm_auth_fuzz_key();
  const std::span<const std::uint8_t> message(data, size);

  auto forged = cosmic::LcmAuthVerifier::make(key, 1s).value();
  const cosmic::LcmAuthCheck as_sent = forged.check("obstacle", message, kNow);
  require(as_sent.verdict != cosmic::LcmAuthVerdict::authentic);
  require(as_sent.message_size == 0);

  auto signer = cosmic::LcmAuthSigner::make(key, 0x5eed).value();
  cosmic::LcmAuthTrailer trailer{};
  require(signer.sign("obstacle", std::span(&message, 1), kNow, trailer));
  std::vector<std::uint8_t> wire(data, data + size);
  wire.insert(wire.end(), trailer.begin(), trailer.end());
  auto verifier = cosmic::LcmAuthVerifier::make(key, 1s).value();
  const cosmic::LcmAuthCheck signed_check = verifier.check("obstacle", wire, kNow);
  require(signed_check.verdict == cosmic::LcmAuthVerdict::authentic);
  require(signed_check.message_size == size);
  require(verifier.check("obstacle", wire, kNow).verdict == cosmic::LcmAuthVerdict::replayed);
  if (!wire.empty()) {
    wire[size % wire.size()] ^= 0x01;
    auto fresh = cosmic::LcmAuthVerifier::make(key, 1s).value();
    require(fresh.check("obstacle", wire, kNow).verdict == cosmic::LcmAuthVerdict::unauthenticated);
  }
  return 0;
}

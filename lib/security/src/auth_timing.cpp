#include "cosmic/auth_timing.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include "cosmic/lcm_auth.hpp"

namespace cosmic {
namespace {

Nanos elapsed_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now() - start);
}

Nanos percentile(const std::vector<Nanos>& sorted, double fraction) {
  if (sorted.empty()) return Nanos(0);
  const auto index = static_cast<std::size_t>(fraction * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

}  // namespace

AuthTiming time_lcm_auth(std::size_t message_bytes, std::size_t runs) {
  AuthTiming out;
  out.message_bytes = message_bytes;
  // A key of the usual size; the cost does not depend on its bytes.
  std::vector<std::uint8_t> key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(i * 37 + 11);
  auto signer = LcmAuthSigner::make(key, 1);
  auto verifier = LcmAuthVerifier::make(key, std::chrono::hours(1));
  if (!signer || !verifier || runs == 0) return out;
  std::vector<std::uint8_t> message(message_bytes + kLcmAuthTrailerSize, 0x5a);
  const std::span<const std::uint8_t> body = std::span(message).first(message_bytes);
  std::vector<Nanos> samples;
  samples.reserve(runs);
  const std::int64_t now = 1'790'000'000'000'000'000;
  for (std::size_t i = 0; i < runs; ++i) {
    LcmAuthTrailer trailer{};
    auto start = std::chrono::steady_clock::now();
    signer.value().sign("calibration", std::span(&body, 1), now, trailer);
    const Nanos signing = elapsed_since(start);
    std::copy(trailer.begin(), trailer.end(), message.begin() + static_cast<std::ptrdiff_t>(message_bytes));
    start = std::chrono::steady_clock::now();
    verifier.value().check("calibration", message, now);
    samples.push_back(std::max(signing, elapsed_since(start)));
  }
  std::sort(samples.begin(), samples.end());
  out.runs = runs;
  out.p50 = percentile(samples, 0.50);
  out.p99 = percentile(samples, 0.99);
  out.p999 = percentile(samples, 0.999);
  out.max = samples.back();
  return out;
}

}  // namespace cosmic

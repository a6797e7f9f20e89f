#include "cosmic/auth_timing.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include "cosmic/lcm_auth.hpp"
#include "cosmic/secoc.hpp"

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

AuthTiming timing_summary(std::size_t bytes, std::vector<Nanos>& samples) {
  AuthTiming out;
  out.message_bytes = bytes;
  if (samples.empty()) return out;
  std::sort(samples.begin(), samples.end());
  out.runs = samples.size();
  out.p50 = percentile(samples, 0.50);
  out.p99 = percentile(samples, 0.99);
  out.p999 = percentile(samples, 0.999);
  out.max = samples.back();
  return out;
}

AuthTiming time_secoc(std::size_t data_bytes, unsigned mac_bits, unsigned freshness_bits, std::size_t runs) {
  const std::vector<std::uint8_t> key(kSecocKeyBytes, 0x2b);
  SecocParameters parameters;
  parameters.data_id = 0x123;
  parameters.mac_bits = mac_bits;
  parameters.freshness_bits = freshness_bits;
  auto sender = SecocSender::make(key, parameters, 0);
  auto receiver = SecocReceiver::make(key, parameters, 0);
  std::vector<Nanos> samples;
  if (!sender || !receiver) return timing_summary(data_bytes, samples);
  std::vector<std::uint8_t> data(data_bytes, 0x5a);
  std::vector<std::uint8_t> frame(data_bytes + secoc_overhead_bytes(parameters));
  samples.reserve(runs);
  for (std::size_t i = 0; i < runs; ++i) {
    auto start = std::chrono::steady_clock::now();
    const std::size_t size = sender.value().protect(data, frame);
    const Nanos protecting = elapsed_since(start);
    start = std::chrono::steady_clock::now();
    receiver.value().verify(std::span(frame).first(size));
    samples.push_back(std::max(protecting, elapsed_since(start)));
  }
  return timing_summary(data_bytes, samples);
}

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

// What authentication costs per message on this machine (issue 36): the LCM trailer signed by a
// sender and checked by a receiver (HMAC-SHA256 over the channel name and the message), and a SecOC
// frame protected and verified (AES-128-CMAC over data ID, data and freshness). Google Benchmark;
// figures in the closing notes and docs/security.md, never a pass/fail test.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "cosmic/lcm_auth.hpp"
#include "cosmic/secoc.hpp"

namespace {

using namespace std::chrono_literals;

std::vector<std::uint8_t> bench_key(std::size_t n) {
  std::vector<std::uint8_t> key(n);
  for (std::size_t i = 0; i < n; ++i) key[i] = static_cast<std::uint8_t>(i * 17 + 3);
  return key;
}

void BM_LcmAuthSign(benchmark::State& state) {
  const std::vector<std::uint8_t> message(static_cast<std::size_t>(state.range(0)), 0x5a);
  auto signer = cosmic::LcmAuthSigner::make(bench_key(32), 1).value();
  const std::span<const std::uint8_t> part(message);
  cosmic::LcmAuthTrailer trailer{};
  std::int64_t now = 1'790'000'000'000'000'000;
  for (auto _ : state) benchmark::DoNotOptimize(signer.sign("obstacle", std::span(&part, 1), ++now, trailer));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_LcmAuthSign)->Arg(16)->Arg(64)->Arg(1024)->Arg(16384);

void BM_LcmAuthCheck(benchmark::State& state) {
  const std::size_t size = static_cast<std::size_t>(state.range(0));
  const std::vector<std::uint8_t> message(size, 0x5a);
  auto signer = cosmic::LcmAuthSigner::make(bench_key(32), 1).value();
  const std::span<const std::uint8_t> part(message);
  const std::int64_t now = 1'790'000'000'000'000'000;
  // Signed ahead: each check takes a new sequence number, as a stream of messages does.
  std::vector<std::vector<std::uint8_t>> wire(4096);
  for (auto& w : wire) {
    cosmic::LcmAuthTrailer trailer{};
    signer.sign("obstacle", std::span(&part, 1), now, trailer);
    w = message;
    w.insert(w.end(), trailer.begin(), trailer.end());
  }
  auto verifier = cosmic::LcmAuthVerifier::make(bench_key(32), 1s).value();
  std::size_t i = 0;
  for (auto _ : state) {
    // Past the signed ones the numbers repeat: still a whole check (tag, window), verdict replayed.
    benchmark::DoNotOptimize(verifier.check("obstacle", wire[i++ % wire.size()], now));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_LcmAuthCheck)->Arg(16)->Arg(64)->Arg(1024)->Arg(16384);

void BM_SecocProtect(benchmark::State& state) {
  const cosmic::SecocParameters parameters{0x123, 24, 8};
  auto sender = cosmic::SecocSender::make(bench_key(16), parameters, 0).value();
  const std::vector<std::uint8_t> data(static_cast<std::size_t>(state.range(0)), 0x11);
  std::vector<std::uint8_t> frame(64);
  for (auto _ : state) benchmark::DoNotOptimize(sender.protect(data, frame));
}
BENCHMARK(BM_SecocProtect)->Arg(4)->Arg(60);

void BM_SecocVerify(benchmark::State& state) {
  const cosmic::SecocParameters parameters{0x123, 24, 8};
  auto sender = cosmic::SecocSender::make(bench_key(16), parameters, 0).value();
  auto receiver = cosmic::SecocReceiver::make(bench_key(16), parameters, 0).value();
  const std::vector<std::uint8_t> data(static_cast<std::size_t>(state.range(0)), 0x11);
  std::vector<std::uint8_t> frame(64);
  for (auto _ : state) {
    state.PauseTiming();
    const std::size_t n = sender.protect(data, frame);
    state.ResumeTiming();
    benchmark::DoNotOptimize(receiver.verify(std::span(frame).first(n)));
  }
}
BENCHMARK(BM_SecocVerify)->Arg(4)->Arg(60);

}  // namespace

BENCHMARK_MAIN();

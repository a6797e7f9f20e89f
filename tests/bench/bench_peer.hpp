// What the transports of cosmic-bench-peer share (bench_peer.cpp: LCM and main; bench_dds.cpp:
// Fast DDS): the clock, the payload layout (bench_peer.cpp's header comment), the publisher's
// pacing loop and the receiver's statistics.
#pragma once

#include <algorithm>
#include <atomic>
#include <cinttypes>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace cosmic_bench {

inline constexpr std::uint32_t kWarmupBit = 0x80000000u;
inline constexpr std::size_t kMinSize = 16;

// Set by SIGTERM/SIGINT: every loop ends.
inline std::atomic<bool> g_stop{false};
// Set by a publisher whose transport stopped taking events (dds-pub: no write succeeded for
// --stall seconds): the run ends early and says so.
inline bool g_stalled = false;
// --zero-fill: bytes 16.. of every payload are 0, not the index pattern, so that a typed channel's
// compact event (scripts/bench's typed path) holds valid values (zero numbers, false bools).
inline bool g_zero_fill = false;

std::int64_t mono_ns();
// CPU time of this whole process (every thread: the transport's too).
std::int64_t process_cpu_ns();
void sleep_until_ns(std::int64_t t);
void put_le(std::uint8_t* p, std::uint64_t v, int bytes);
std::uint64_t get_le(const std::uint8_t* p, int bytes);
// Bytes 8.. of the payload for event `index` (the stamp, bytes 0..7, is written by stamp()).
void fill(std::vector<std::uint8_t>& payload, std::uint32_t index);
void stamp(std::vector<std::uint8_t>& payload);
void err_line(const std::string& text);

// Drives a publisher: warm-up, pause, measured events. send(payload) returns false on failure.
// Measured event k is due at start + (k - 1) / rate. With max_rate > 0 the publisher keeps a
// channel contract of that rate as a real component would: after a stall (this process not
// scheduled) it catches up no faster than max_rate instead of sending the missed events back to
// back, which would exceed its contract. How late events went out against their schedule is
// reported (late_max_us, late_over_1ms): that is the machine delaying the publisher, not the
// network after it.
template <typename Send>
int publish_all(std::uint64_t count, std::uint64_t size, double rate, std::uint64_t warmup, Send&& send,
                double max_rate = 0) {
  std::vector<std::uint8_t> payload(std::max<std::uint64_t>(size, kMinSize));
  const double warm_rate = rate > 0 ? std::min(rate, 5000.0) : 5000.0;
  const std::int64_t min_gap = max_rate > 0 ? static_cast<std::int64_t>(1e9 / max_rate) : 0;
  std::int64_t last_send = 0;
  std::int64_t start = mono_ns();
  for (std::uint64_t k = 1; k <= warmup && !g_stop && !g_stalled; ++k) {
    const std::int64_t scheduled = start + static_cast<std::int64_t>(static_cast<double>(k - 1) * 1e9 / warm_rate);
    sleep_until_ns(k > 1 ? std::max(scheduled, last_send + min_gap) : scheduled);
    last_send = mono_ns();
    fill(payload, kWarmupBit | static_cast<std::uint32_t>(k));
    stamp(payload);
    send(payload);
  }
  if (warmup > 0) sleep_until_ns(mono_ns() + 200'000'000);
  std::uint64_t sent = 0;
  std::uint64_t failed = 0;
  std::int64_t late_max = 0;
  std::uint64_t late_over_1ms = 0;
  start = mono_ns();
  const std::int64_t start_cpu = process_cpu_ns();
  for (std::uint64_t k = 1; k <= count && !g_stop && !g_stalled; ++k) {
    if (rate > 0) {
      const std::int64_t scheduled = start + static_cast<std::int64_t>(static_cast<double>(k - 1) * 1e9 / rate);
      sleep_until_ns(k > 1 ? std::max(scheduled, last_send + min_gap) : scheduled);
      last_send = mono_ns();
      late_max = std::max(late_max, last_send - scheduled);
      if (last_send - scheduled > 1'000'000) ++late_over_1ms;
    }
    fill(payload, static_cast<std::uint32_t>(k));
    stamp(payload);
    if (send(payload)) {
      ++sent;
    } else {
      ++failed;
    }
  }
  const double seconds = static_cast<double>(mono_ns() - start) / 1e9;
  const double cpu_us = static_cast<double>(process_cpu_ns() - start_cpu) / 1e3;
  std::printf("RESULT sent=%" PRIu64 " failed=%" PRIu64
              " seconds=%.6f rate=%.0f stalled=%d late_max_us=%.1f"
              " late_over_1ms=%" PRIu64 " cpu_us_per_event=%.2f\n",
              sent, failed, seconds, seconds > 0 ? static_cast<double>(sent) / seconds : 0.0, g_stalled ? 1 : 0,
              static_cast<double>(late_max) / 1e3, late_over_1ms, sent > 0 ? cpu_us / static_cast<double>(sent) : 0.0);
  std::fflush(stdout);
  if (g_stalled) return 5;
  return failed == 0 && !g_stop ? 0 : 4;
}

// Receiver statistics. record() runs on one thread at a time (the transport's callback).
class Recorder {
 public:
  explicit Recorder(std::uint64_t count) : count_(count), seen_(count + 1, 0) { latency_ns_.reserve(count); }

  // One event's payload as the publisher wrote it (size < kMinSize: counted as malformed).
  void record(const std::uint8_t* data, std::size_t size, std::int64_t now);
  // Waits until every measured event arrived, the flow went idle, or the timeout.
  void wait(double timeout_s, double idle_s);
  // Prints the RESULT line; 0 when a measured event arrived, 1 otherwise.
  int report();

  std::string dump_path;  // --dump: one line per measured event "index sent_ns recv_ns latency_us"

 private:
  struct Trace {
    std::uint32_t index;
    std::int64_t sent_ns;
    std::int64_t recv_ns;
  };

  std::vector<Trace> trace_;
  std::uint64_t count_;
  std::vector<std::uint8_t> seen_;
  std::vector<std::int64_t> latency_ns_;
  std::uint64_t received_ = 0;
  std::uint64_t duplicates_ = 0;
  std::uint64_t warmup_received_ = 0;
  std::uint64_t malformed_ = 0;
  std::int64_t first_ns_ = 0;
  std::int64_t first_cpu_ns_ = 0;  // the process's CPU time at the first measured event
  std::int64_t last_ns_ = 0;
  std::atomic<std::int64_t> last_any_ns_{0};
  std::atomic<bool> measuring_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
};

}  // namespace cosmic_bench

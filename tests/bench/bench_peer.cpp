// cosmic-bench-peer: load generator and latency receiver of scripts/bench, for LCM and Fast DDS,
// each side in its own process. The same code measures the native paths (LCM -> LCM,
// DDS -> DDS) and the paths through cosmicd, so the only difference between them is the gateway.
//
//   cosmic-bench-peer lcm-pub --url U --channel C --count N --size B [--rate HZ] [--warmup W] [--max-rate HZ]
//                             [--zero-fill]
//                             [--envelope]
//   cosmic-bench-peer lcm-sub --url U --channel C --count N [--timeout S] [--idle S] [--envelope]
//                             [--dump FILE]
//   cosmic-bench-peer dds-pub --domain D --topic T --count N --size B [--rate HZ] [--warmup W]
//                             [--max-rate HZ] [--keep-last DEPTH] [--default-heartbeat] [--wait-go]
//                             [--match-timeout S] [--stall S]
//                             [--native TYPE] [--pki DIR --identity NAME [--governance FILE]]
//   cosmic-bench-peer dds-sub --domain D --topic T --count N [--timeout S] [--idle S] [--dump FILE]
//                             [--keep-last DEPTH]
//                             [--native TYPE] [--pki DIR --identity NAME [--governance FILE]]
//
// Payload of every event (size >= 16): bytes 0..7 = CLOCK_MONOTONIC ns when the publisher hands
// it to its library (little-endian), bytes 8..11 = index (measured events 1..N, warm-up events
// 0x80000000 | k, little-endian), the rest (index + i) & 0xff (0 with --zero-fill). The stamp travels in the payload,
// which the gateway forwards unchanged, so one-way latency = receive time - stamp on every path
// (all processes of one host read the same CLOCK_MONOTONIC). LCM events are the bare payload
// (cosmicd channel encoding raw) unless --envelope; DDS events are cosmic::Envelope with origin 0
// (a native source), sequence = index and created_ns = the stamp, or with --native TYPE samples of
// a raw type announced as TYPE (a cosmicd native topic): the bytes written are a CDR
// encapsulation header 00 01 00 00 (CDR_LE, XCDR1) followed by the B-byte payload, so the stamp
// sits at bytes 4..11 of the sample (the receiver skips the header, and counts a sample without
// exactly that header as malformed). With --identity NAME the DDS participant is a secure one
// (DDS Security with the builtin plugins, as cosmicd's on a segment with `security:`): identity
// NAME of the PKI in DIR (tests/support/make_test_pki.sh's layout), governed by FILE (default
// DIR/governance.p7s). The Fast DDS side is bench_dds.cpp.
//
// Publishers first send W warm-up events (default 200, paced at min(rate, 5000)/s; they let
// discovery settle and warm caches and are ignored by the receiver), pause 200 ms, then the N
// measured events at --rate (0: as fast as possible); with --max-rate (the channel's contract) a
// publisher the machine held up catches up no faster than that rate. dds-pub waits until a reader matched
// (exit 2 after --match-timeout), and with --wait-go prints WAITING on stderr and reads one line
// on stdin before sending (the caller first checks the far side has matched us too). dds-pub's
// writer is reliable, KEEP_ALL or --keep-last DEPTH, synchronous, heartbeat every 50 ms (Fast
// DDS's default, 3 s, with --default-heartbeat); dds-sub's reader is reliable, KEEP_ALL or
// --keep-last DEPTH.
//
// Receivers print READY (lcm-sub, once subscribed) or MATCHED (dds-sub, once its reader matched a
// writer) on stderr. They stop when all N measured events arrived, after --idle seconds without
// any event once measured events flow (default 1.5 s), or at --timeout (default 60 s).
//
// Each program ends with one line on stdout: "RESULT key=value ...".
//   pub: sent failed seconds rate (measured events only) stalled (dds-pub: 1 when the reader side
//        stopped accepting events for --stall seconds, default 5; the run then ends, exit 5)
//        late_max_us late_over_1ms (how late against its schedule the publisher got to send)
//   sub: expected received lost duplicates malformed p50_us p90_us p99_us p999_us max_us mean_us
//        span_s rate (measured events per second between the first and the last arrival)
//        warmup_received
// Exit 0 on success; 1 when a receiver got no measured event, 2 no match, 3 setup failure,
// 4 a send failed, 5 dds-pub stalled.
#include <lcm/lcm.h>
#include <signal.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include <fastdds/dds/log/Log.hpp>

#include "bench_dds.hpp"
#include "bench_peer.hpp"
#include "cosmic/envelope.hpp"  // lcm-gen

namespace cosmic_bench {

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::int64_t process_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t) {
  // Already due: no system call (clock_nanosleep with a past deadline still costs about 15 us on
  // a virtual machine, which alone kept a 20 kHz publisher at 14k events/s).
  if (t <= mono_ns()) return;
  timespec ts{};
  ts.tv_sec = t / 1'000'000'000;
  ts.tv_nsec = t % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR && !g_stop) {
  }
}

void put_le(std::uint8_t* p, std::uint64_t v, int bytes) {
  for (int b = 0; b < bytes; ++b) p[b] = static_cast<std::uint8_t>(v >> (8 * b));
}
std::uint64_t get_le(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int b = 0; b < bytes; ++b) v |= std::uint64_t{p[b]} << (8 * b);
  return v;
}

void fill(std::vector<std::uint8_t>& payload, std::uint32_t index) {
  for (std::size_t i = 16; i < payload.size(); ++i)
    payload[i] = g_zero_fill ? std::uint8_t{0} : static_cast<std::uint8_t>((index + i) & 0xff);
  put_le(payload.data() + 8, index, 4);
  put_le(payload.data() + 12, 0, 4);
}

void stamp(std::vector<std::uint8_t>& payload) { put_le(payload.data(), static_cast<std::uint64_t>(mono_ns()), 8); }

void err_line(const std::string& text) {
  std::fputs((text + "\n").c_str(), stderr);
  std::fflush(stderr);
}

void Recorder::record(const std::uint8_t* data, std::size_t size, std::int64_t now) {
  std::lock_guard lock(mutex_);  // uncontended but for the final report
  last_any_ns_.store(now, std::memory_order_relaxed);
  if (size < kMinSize) {
    ++malformed_;
    return;
  }
  const auto index = static_cast<std::uint32_t>(get_le(data + 8, 4));
  if ((index & kWarmupBit) != 0) {
    ++warmup_received_;
    return;
  }
  if (index == 0 || index > count_) {
    ++malformed_;
    return;
  }
  if (seen_[index] != 0) {
    ++duplicates_;
    return;
  }
  seen_[index] = 1;
  const auto sent = static_cast<std::int64_t>(get_le(data, 8));
  latency_ns_.push_back(now - sent);
  if (!dump_path.empty()) trace_.push_back({index, sent, now});
  if (received_ == 0) {
    first_ns_ = now;
    first_cpu_ns_ = process_cpu_ns();
  }
  last_ns_ = now;
  measuring_.store(true, std::memory_order_relaxed);
  if (++received_ >= count_) {
    done_ = true;
    cv_.notify_all();
  }
}

void Recorder::wait(double timeout_s, double idle_s) {
  const std::int64_t deadline = mono_ns() + static_cast<std::int64_t>(timeout_s * 1e9);
  const auto idle_ns = static_cast<std::int64_t>(idle_s * 1e9);
  std::unique_lock lock(mutex_);
  while (!done_ && !g_stop) {
    cv_.wait_for(lock, std::chrono::milliseconds(20));
    const std::int64_t now = mono_ns();
    if (now >= deadline) break;
    if (measuring_.load(std::memory_order_relaxed) && now - last_any_ns_.load(std::memory_order_relaxed) > idle_ns)
      break;
  }
}

int Recorder::report() {
  const std::int64_t cpu_now = process_cpu_ns();  // before the sorting and the dump below
  std::lock_guard lock(mutex_);                   // record() may still run on the transport's thread
  if (!dump_path.empty()) {
    if (FILE* f = std::fopen(dump_path.c_str(), "w")) {
      for (const auto& t : trace_)
        std::fprintf(f, "%" PRIu32 " %" PRId64 " %" PRId64 " %.1f\n", t.index, t.sent_ns, t.recv_ns,
                     static_cast<double>(t.recv_ns - t.sent_ns) / 1e3);
      std::fclose(f);
    }
  }
  std::vector<std::int64_t> lat(latency_ns_);
  std::sort(lat.begin(), lat.end());
  auto q = [&](double p) -> double {
    if (lat.empty()) return 0;
    const auto i = static_cast<std::size_t>(p * static_cast<double>(lat.size() - 1) + 0.5);
    return static_cast<double>(lat[std::min(i, lat.size() - 1)]) / 1e3;
  };
  double mean = 0;
  for (const auto v : lat) mean += static_cast<double>(v);
  mean = lat.empty() ? 0 : mean / static_cast<double>(lat.size()) / 1e3;
  const double span = received_ > 1 ? static_cast<double>(last_ns_ - first_ns_) / 1e9 : 0;
  std::printf(
      "RESULT expected=%" PRIu64 " received=%" PRIu64 " lost=%" PRIu64 " duplicates=%" PRIu64 " malformed=%" PRIu64
      " p50_us=%.1f p90_us=%.1f p99_us=%.1f p999_us=%.1f max_us=%.1f mean_us=%.1f span_s=%.6f rate=%.0f"
      " warmup_received=%" PRIu64 " cpu_us_per_event=%.2f\n",
      count_, received_, count_ - received_, duplicates_, malformed_, q(0.50), q(0.90), q(0.99), q(0.999),
      lat.empty() ? 0.0 : static_cast<double>(lat.back()) / 1e3, mean, span,
      span > 0 ? static_cast<double>(received_ - 1) / span : 0.0, warmup_received_,
      received_ > 0 ? static_cast<double>(cpu_now - first_cpu_ns_) / 1e3 / static_cast<double>(received_) : 0.0);
  std::fflush(stdout);
  return received_ > 0 ? 0 : 1;
}

}  // namespace cosmic_bench

namespace {

using namespace cosmic_bench;

void on_signal(int) { g_stop = true; }

// ---- LCM ---------------------------------------------------------------------------------------

std::string channel_regex(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (std::strchr(".[]{}()\\*+?|^$", c) != nullptr) out.push_back('\\');
    out.push_back(c);
  }
  return out;
}

struct LcmOptions {
  std::string url;
  std::string channel;
  std::uint64_t count = 0;
  std::uint64_t size = 64;
  double rate = 0;
  double max_rate = 0;
  std::uint64_t warmup = 200;
  bool envelope = false;
  double timeout = 60;
  double idle = 1.5;
  std::string dump;
};

int lcm_pub(const LcmOptions& o) {
  lcm_t* lcm = lcm_create(o.url.c_str());
  if (lcm == nullptr) {
    err_line("lcm_create failed for " + o.url);
    return 3;
  }
  cosmic::envelope e{};
  std::vector<std::uint8_t> buffer;
  const int rc = publish_all(
      o.count, o.size, o.rate, o.warmup,
      [&](const std::vector<std::uint8_t>& payload) {
        if (!o.envelope) {
          return lcm_publish(lcm, o.channel.c_str(), payload.data(), static_cast<unsigned>(payload.size())) == 0;
        }
        e.sequence = static_cast<std::int32_t>(get_le(payload.data() + 8, 4));
        e.created_ns = static_cast<std::int64_t>(get_le(payload.data(), 8));
        e.payload_size = static_cast<std::int32_t>(payload.size());
        e.payload = payload;
        buffer.resize(static_cast<std::size_t>(e.getEncodedSize()));
        e.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
        return lcm_publish(lcm, o.channel.c_str(), buffer.data(), static_cast<unsigned>(buffer.size())) == 0;
      },
      o.max_rate);
  lcm_destroy(lcm);
  return rc;
}

struct LcmSubState {
  Recorder* recorder;
  bool envelope;
  cosmic::envelope e{};
};

void lcm_on_message(const lcm_recv_buf_t* rbuf, const char*, void* user) {
  const std::int64_t now = mono_ns();
  auto& s = *static_cast<LcmSubState*>(user);
  const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
  if (!s.envelope) {
    s.recorder->record(data, rbuf->data_size, now);
    return;
  }
  if (s.e.decode(data, 0, static_cast<int>(rbuf->data_size)) < 0) {
    s.recorder->record(data, 0, now);  // counted as malformed
    return;
  }
  s.recorder->record(s.e.payload.data(), static_cast<std::size_t>(s.e.payload_size), now);
}

int lcm_sub(const LcmOptions& o) {
  lcm_t* lcm = lcm_create(o.url.c_str());
  if (lcm == nullptr) {
    err_line("lcm_create failed for " + o.url);
    return 3;
  }
  // Receive side (socket, group membership, LCM's reader thread) set up before subscribing.
  if (lcm_get_fileno(lcm) < 0) {
    err_line("LCM receive setup failed for " + o.url);
    lcm_destroy(lcm);
    return 3;
  }
  Recorder recorder(o.count);
  recorder.dump_path = o.dump;
  LcmSubState state{&recorder, o.envelope};
  lcm_subscription_t* sub = lcm_subscribe(lcm, channel_regex(o.channel).c_str(), &lcm_on_message, &state);
  if (sub == nullptr) {
    err_line("lcm_subscribe failed");
    lcm_destroy(lcm);
    return 3;
  }
  lcm_subscription_set_queue_capacity(sub, 1 << 20);
  err_line("READY");
  std::thread handler([&] {
    while (!g_stop.load(std::memory_order_relaxed)) {
      if (lcm_handle_timeout(lcm, 50) < 0) {
        err_line("lcm_handle failed");
        g_stop = true;
      }
    }
  });
  recorder.wait(o.timeout, o.idle);
  g_stop = true;
  handler.join();
  const int rc = recorder.report();
  lcm_destroy(lcm);
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  eprosima::fastdds::dds::Log::SetVerbosity(eprosima::fastdds::dds::Log::Error);

  CLI::App app{"cosmic-bench-peer: load generator and latency receiver for scripts/bench"};
  app.require_subcommand(1);
  LcmOptions lo;
  DdsOptions dd;
  auto lcm_common = [&](CLI::App* c) {
    c->add_option("--url", lo.url, "LCM URL")->required();
    c->add_option("--channel", lo.channel, "LCM channel")->required();
    c->add_option("--count", lo.count, "measured events")->required();
    c->add_flag("--envelope", lo.envelope, "cosmic.envelope instead of raw bytes");
  };
  auto dds_common = [&](CLI::App* c) {
    c->add_option("--domain", dd.domain, "DDS domain")->required();
    c->add_option("--topic", dd.topic, "DDS topic (cosmicd: cosmic/<channel>)")->required();
    c->add_option("--count", dd.count, "measured events")->required();
    c->add_option("--native", dd.native_type,
                  "type name of a native topic: samples are 00 01 00 00 + payload instead of cosmic::Envelope");
    c->add_option("--pki", dd.pki, "DDS Security: the PKI's directory (tests/support/make_test_pki.sh)");
    auto* identity =
        c->add_option("--identity", dd.identity, "DDS Security: a secure participant as NAME (NAME_cert.pem)");
    identity->needs(c->get_option("--pki"));
    c->add_option("--governance", dd.governance, "DDS Security: the signed governance (default PKI/governance.p7s)")
        ->needs(identity);
  };
  CLI::App* lp = app.add_subcommand("lcm-pub", "publish on LCM");
  lcm_common(lp);
  lp->add_option("--size", lo.size, "payload bytes (>= 16)");
  lp->add_option("--rate", lo.rate, "events/s (0: as fast as possible)");
  lp->add_option("--max-rate", lo.max_rate, "the channel's max_rate: catch up after a stall no faster than this");
  lp->add_option("--warmup", lo.warmup, "warm-up events");
  lp->add_flag("--zero-fill", g_zero_fill, "bytes 16.. are 0 (a typed channel's compact event), not the index pattern");
  CLI::App* ls = app.add_subcommand("lcm-sub", "receive on LCM");
  lcm_common(ls);
  ls->add_option("--timeout", lo.timeout, "seconds");
  ls->add_option("--idle", lo.idle, "seconds without events that end the run");
  ls->add_option("--dump", lo.dump, "write 'index sent_ns recv_ns latency_us' per event to this file");
  CLI::App* dp = app.add_subcommand("dds-pub", "publish on DDS");
  dds_common(dp);
  dp->add_option("--size", dd.size, "payload bytes (>= 16)");
  dp->add_option("--rate", dd.rate, "events/s (0: as fast as possible)");
  dp->add_option("--max-rate", dd.max_rate, "the channel's max_rate: catch up after a stall no faster than this");
  dp->add_option("--warmup", dd.warmup, "warm-up events");
  dp->add_option("--keep-last", dd.keep_last, "KEEP_LAST depth (default KEEP_ALL)");
  dp->add_flag("--default-heartbeat", dd.default_heartbeat, "Fast DDS's default heartbeat period (3 s), not 50 ms");
  dp->add_flag("--wait-go", dd.wait_go, "after matching, wait for a line on stdin");
  dp->add_option("--match-timeout", dd.match_timeout, "seconds to wait for a reader");
  dp->add_option("--stall", dd.stall, "give up (exit 5) when no write succeeds for this many seconds");
  CLI::App* ds = app.add_subcommand("dds-sub", "receive on DDS");
  dds_common(ds);
  ds->add_option("--timeout", dd.timeout, "seconds");
  ds->add_option("--keep-last", dd.keep_last, "KEEP_LAST depth (default KEEP_ALL)");
  ds->add_option("--idle", dd.idle, "seconds without events that end the run");
  ds->add_option("--dump", dd.dump, "write 'index sent_ns recv_ns latency_us' per event to this file");
  CLI11_PARSE(app, argc, argv);

  int rc = 3;
  if (lp->parsed()) rc = lcm_pub(lo);
  if (ls->parsed()) rc = lcm_sub(lo);
  if (dp->parsed()) rc = dds_pub(dd);
  if (ds->parsed()) rc = dds_sub(dd);
  eprosima::fastdds::dds::Log::Flush();
  return rc;
}

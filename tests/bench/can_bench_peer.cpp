// cosmic-can-bench: one CAN -> CAN forwarding run for scripts/bench's CAN section (run inside
// scripts/can-vm). Sends --count standard frames with identifier --id on --in, numbered in their
// first four data bytes, paced at --rate frames/s (0: as fast as the socket takes them), and
// watches --in and --out with the kernel's receive timestamps (SO_TIMESTAMPNS): the latency of a
// frame is its timestamp on --out minus its timestamp on --in, both taken by the kernel, so the
// watcher's own scheduling adds nothing. Whoever forwards (cosmicd, the kernel's cangw) is
// outside. Prints one JSON object. The interface counters, which count what the forwarder wrote
// even where a watching socket would drop frames, are read by the calling script.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

constexpr std::int64_t kUnseen = -1;

std::int64_t now_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

int open_can(const std::string& interface, canid_t id, int receive_buffer) {
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (s < 0) throw std::runtime_error("socket(PF_CAN): " + std::string(std::strerror(errno)));
  const can_filter filter{id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG};
  const int on = 1;
  ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter);
  ::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  // The watcher must not be the one losing frames: as much buffer as root may force.
  if (receive_buffer > 0 && ::setsockopt(s, SOL_SOCKET, SO_RCVBUFFORCE, &receive_buffer, sizeof receive_buffer) != 0) {
    ::setsockopt(s, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(if_nametoindex(interface.c_str()));
  if (addr.can_ifindex == 0) throw std::runtime_error("no interface " + interface);
  if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    throw std::runtime_error("bind " + interface + ": " + std::strerror(errno));
  }
  return s;
}

// Records the kernel timestamp of every numbered frame of this run (tag) that reaches `socket`.
class Watcher {
 public:
  Watcher(int socket, std::size_t count, std::uint32_t tag, const char* name)
      : socket_(socket), tag_(tag), stamps_(count, kUnseen), name_(name) {}
  void start() {
    thread_ = std::thread([this] { run(); });
  }
  void stop() {
    stopping_ = true;
    thread_.join();
  }
  std::size_t seen() const { return seen_.load(); }
  std::int64_t last_arrival() const { return last_arrival_.load(); }
  std::size_t reordered() const { return reordered_; }
  std::size_t duplicates() const { return duplicates_; }
  const std::vector<std::int64_t>& stamps() const { return stamps_; }

 private:
  void run() {
    pthread_setname_np(pthread_self(), name_);
    constexpr std::size_t kBatch = 64;
    std::vector<can_frame> frames(kBatch);
    std::vector<iovec> iovs(kBatch);
    std::vector<mmsghdr> messages(kBatch);
    std::vector<std::array<char, CMSG_SPACE(sizeof(timespec))>> controls(kBatch);
    std::int64_t highest = -1;
    while (!stopping_) {
      pollfd pfd{socket_, POLLIN, 0};
      if (::poll(&pfd, 1, 50) <= 0) continue;
      for (std::size_t i = 0; i < kBatch; ++i) {
        iovs[i] = iovec{&frames[i], sizeof(can_frame)};
        messages[i] = mmsghdr{};
        messages[i].msg_hdr.msg_iov = &iovs[i];
        messages[i].msg_hdr.msg_iovlen = 1;
        messages[i].msg_hdr.msg_control = controls[i].data();
        messages[i].msg_hdr.msg_controllen = controls[i].size();
      }
      const int n = ::recvmmsg(socket_, messages.data(), kBatch, MSG_DONTWAIT, nullptr);
      for (int i = 0; i < n; ++i) {
        const can_frame& f = frames[static_cast<std::size_t>(i)];
        if (f.len < 8) continue;
        std::uint32_t sequence = 0;
        std::uint32_t tag = 0;
        std::memcpy(&sequence, f.data, 4);
        std::memcpy(&tag, f.data + 4, 4);
        if (tag != tag_ || sequence >= stamps_.size()) continue;
        std::int64_t stamp = 0;
        for (cmsghdr* c = CMSG_FIRSTHDR(&messages[static_cast<std::size_t>(i)].msg_hdr); c;
             c = CMSG_NXTHDR(&messages[static_cast<std::size_t>(i)].msg_hdr, c)) {
          if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
            timespec ts{};
            std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
            stamp = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
          }
        }
        if (stamps_[sequence] != kUnseen) {
          ++duplicates_;
          continue;
        }
        stamps_[sequence] = stamp;
        if (static_cast<std::int64_t>(sequence) < highest) ++reordered_;
        highest = std::max<std::int64_t>(highest, sequence);
        seen_.fetch_add(1);
        last_arrival_ = now_ns(CLOCK_MONOTONIC);
      }
    }
  }

  int socket_;
  std::uint32_t tag_;
  std::vector<std::int64_t> stamps_;
  const char* name_;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::size_t> seen_{0};
  std::atomic<std::int64_t> last_arrival_{0};
  std::size_t reordered_ = 0;
  std::size_t duplicates_ = 0;
};

double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size())));
  return sorted[std::min(sorted.size() - 1, rank == 0 ? 0 : rank - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cosmic-can-bench: one CAN -> CAN forwarding run with kernel timestamps"};
  std::string in;
  std::string out;
  std::string id_text = "0x100";
  std::size_t count = 1000;
  double rate = 1000;
  double idle = 2.0;
  app.add_option("--in", in, "interface the frames are sent on")->required();
  app.add_option("--out", out, "interface the forwarder writes them to")->required();
  app.add_option("--id", id_text, "standard identifier of the frames");
  app.add_option("--count", count, "frames to send")->check(CLI::Range(1, 10'000'000));
  app.add_option("--rate", rate, "frames per second (0: as fast as the socket takes them)")
      ->check(CLI::Range(0.0, 1e7));
  app.add_option("--idle", idle, "seconds without a new frame on --out that end the run")->check(CLI::Range(0.1, 60.0));
  CLI11_PARSE(app, argc, argv);
  try {
    const auto id = static_cast<canid_t>(std::stoul(id_text, nullptr, 0)) & CAN_SFF_MASK;
    const auto tag = static_cast<std::uint32_t>(now_ns(CLOCK_REALTIME));
    const int buffer = static_cast<int>(std::min<std::size_t>(count * 1024 + (1 << 20), 1u << 30));
    Watcher source(open_can(in, id, buffer), count, tag, "bench-watch-in");
    Watcher sink(open_can(out, id, buffer), count, tag, "bench-watch-out");
    const int sender = open_can(in, id, 0);
    const can_filter none{0, 0};
    ::setsockopt(sender, SOL_CAN_RAW, CAN_RAW_FILTER, &none, 0);  // the sender receives nothing
    source.start();
    sink.start();
    const std::int64_t start = now_ns(CLOCK_MONOTONIC);
    std::size_t refused = 0;
    for (std::size_t i = 0; i < count; ++i) {
      if (rate > 0) {
        const auto due = start + static_cast<std::int64_t>(static_cast<double>(i) * 1e9 / rate);
        const timespec at{static_cast<time_t>(due / 1'000'000'000), static_cast<long>(due % 1'000'000'000)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
        }
      }
      can_frame frame{};
      frame.can_id = id;
      frame.len = 8;
      const auto sequence = static_cast<std::uint32_t>(i);
      std::memcpy(frame.data, &sequence, 4);
      std::memcpy(frame.data + 4, &tag, 4);
      // A blocking socket: a full transmit queue (ENOBUFS) is waited out, not a lost frame.
      while (::write(sender, &frame, CAN_MTU) != static_cast<ssize_t>(CAN_MTU)) {
        ++refused;
        if (errno != ENOBUFS && errno != EAGAIN && errno != EINTR) throw std::runtime_error(std::strerror(errno));
        std::this_thread::sleep_for(std::chrono::microseconds(100));
      }
    }
    const std::int64_t sent_at = now_ns(CLOCK_MONOTONIC);
    const auto idle_ns = static_cast<std::int64_t>(idle * 1e9);
    while (sink.seen() < count) {
      const std::int64_t last = std::max(sent_at, sink.last_arrival());
      if (now_ns(CLOCK_MONOTONIC) - last > idle_ns) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    source.stop();
    sink.stop();
    std::vector<double> latency_us;
    for (std::size_t i = 0; i < count; ++i) {
      const std::int64_t a = source.stamps()[i];
      const std::int64_t b = sink.stamps()[i];
      if (a != kUnseen && b != kUnseen) latency_us.push_back(static_cast<double>(b - a) / 1e3);
    }
    std::sort(latency_us.begin(), latency_us.end());
    const double send_seconds = static_cast<double>(sent_at - start) / 1e9;
    std::printf(
        "{\"sent\": %zu, \"send_seconds\": %.3f, \"offered_per_s\": %.0f, \"refused_writes\": %zu, "
        "\"seen_in\": %zu, \"received_out\": %zu, \"reordered\": %zu, \"duplicates\": %zu, "
        "\"latency_us\": {\"samples\": %zu, \"p50\": %.1f, \"p99\": %.1f, \"p99_9\": %.1f, \"max\": %.1f}}\n",
        count, send_seconds, send_seconds > 0 ? static_cast<double>(count) / send_seconds : 0.0, refused, source.seen(),
        sink.seen(), sink.reordered(), sink.duplicates(), latency_us.size(), percentile(latency_us, 50),
        percentile(latency_us, 99), percentile(latency_us, 99.9), latency_us.empty() ? 0.0 : latency_us.back());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cosmic-can-bench: %s\n", e.what());
    return 1;
  }
}

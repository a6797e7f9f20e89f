// cosmic-client-peer: a C++ component on libcosmic-client for the Python package's tests and
// benchmark (tests/python). One mode per run; every mode prints READY on stdout once its channels
// are announced, and a JSON line with its figures when done.
//   echo --segment S --in NAME:SUBJECT --out NAME:SUBJECT [--payload N]
//        every event of `in` is published again, unchanged, on `out`, until stdin closes
//   pub  --segment S --channel NAME:SUBJECT [--payload N] [--count N] [--delay-s T] [--rate HZ]
//        N events of N bytes after T seconds (discovery): HZ per second, or as fast as the
//        library takes them (0, the default)
//   sub  --segment S --channel NAME:SUBJECT [--payload N] [--count N] [--seconds T]
//        counts events with a callback until N arrived or T seconds passed
// Exit 0 when the mode did what it was asked (sub: all N arrived), 1 otherwise, 2 on bad use.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <iostream>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/client.hpp"

namespace {

using Clock = std::chrono::steady_clock;

std::string arg(int argc, char** argv, const std::string& name, const std::string& fallback) {
  for (int i = 2; i + 1 < argc; ++i) {
    if (argv[i] == name) return argv[i + 1];
  }
  return fallback;
}

struct ChannelName {
  std::string name;
  std::uint64_t subject = 0;
};

ChannelName channel_arg(int argc, char** argv, const std::string& option) {
  const std::string text = arg(argc, argv, option, "");
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw std::invalid_argument(option + " NAME:SUBJECT is needed");
  return {text.substr(0, colon), std::stoull(text.substr(colon + 1), nullptr, 0)};
}

// An NRT channel, as the Python tests announce it.
cosmic_channel_desc nrt(const ChannelName& c, std::uint32_t payload, int roles) {
  return {c.name.c_str(), c.subject, COSMIC_NRT, 0, 0, 0, 3, payload, roles};
}

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void ready() { std::cout << "READY" << std::endl; }

int echo(int argc, char** argv, cosmic::client::Client& client, std::uint32_t payload) {
  const ChannelName in_name = channel_arg(argc, argv, "--in");
  const ChannelName out_name = channel_arg(argc, argv, "--out");
  auto& out = client.announce(nrt(out_name, payload, COSMIC_PUBLISH));
  auto& in = client.announce(nrt(in_name, payload, COSMIC_SUBSCRIBE));
  std::atomic<std::uint64_t> echoed{0};
  auto on_in = in.on_event([&](const cosmic_event_info&, std::span<const std::uint8_t> e) {
    if (out.publish(e) == COSMIC_OK) ++echoed;
  });
  ready();
  for (std::string line; std::getline(std::cin, line);) {  // the test closes stdin (or dies) to stop it
  }
  on_in.cancel();
  std::cout << "{\"echoed\":" << echoed << "}" << std::endl;
  return 0;
}

int pub(int argc, char** argv, cosmic::client::Client& client, std::uint32_t payload) {
  auto& out = client.announce(nrt(channel_arg(argc, argv, "--channel"), payload, COSMIC_PUBLISH));
  const long count = std::stol(arg(argc, argv, "--count", "10000"));
  ready();
  std::this_thread::sleep_for(std::chrono::duration<double>(std::stod(arg(argc, argv, "--delay-s", "0"))));
  const double rate = std::stod(arg(argc, argv, "--rate", "0"));
  std::vector<std::uint8_t> event(payload, 0x5a);
  long sent = 0, again = 0;
  const auto start = Clock::now();
  for (long i = 0; i < count; ++i) {
    if (rate > 0 && i % 10 == 0) {  // paced in bursts of 10: a sleep per event would oversleep
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(i / rate)));
    }
    std::memcpy(event.data(), &i, std::min(sizeof i, event.size()));
    const int rc = out.publish(event);
    if (rc == COSMIC_OK)
      ++sent;
    else if (rc == COSMIC_E_AGAIN)
      ++again;
    else
      return 1;
  }
  const double took = seconds_since(start);
  std::cout << "{\"published\":" << sent << ",\"again\":" << again << ",\"seconds\":" << took
            << ",\"rate\":" << sent / took << "}" << std::endl;
  return 0;
}

int sub(int argc, char** argv, cosmic::client::Client& client, std::uint32_t payload) {
  auto& in = client.announce(nrt(channel_arg(argc, argv, "--channel"), payload, COSMIC_SUBSCRIBE));
  const std::uint64_t count = std::stoull(arg(argc, argv, "--count", "10000"));
  std::mutex mutex;
  std::condition_variable done;
  std::uint64_t received = 0;
  Clock::time_point first{}, last{};
  auto on_in = in.on_event([&](const cosmic_event_info&, std::span<const std::uint8_t>) {
    std::lock_guard lock(mutex);
    last = Clock::now();
    if (received++ == 0) first = last;
    if (received >= count) done.notify_all();
  });
  ready();
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                           std::stod(arg(argc, argv, "--seconds", "30"))));
  std::unique_lock lock(mutex);
  done.wait_until(lock, deadline, [&] { return received >= count; });
  const double span = std::chrono::duration<double>(last - first).count();
  std::cout << "{\"received\":" << received << ",\"seconds\":" << span
            << ",\"rate\":" << (span > 0 ? (received - 1) / span : 0) << "}" << std::endl;
  const bool all = received >= count;
  lock.unlock();
  on_in.cancel();
  return all ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  try {
    cosmic::client::Client client(arg(argc, argv, "--segment", "dds:0"));
    const auto payload = static_cast<std::uint32_t>(std::stoul(arg(argc, argv, "--payload", "8")));
    if (mode == "echo") return echo(argc, argv, client, payload);
    if (mode == "pub") return pub(argc, argv, client, payload);
    if (mode == "sub") return sub(argc, argv, client, payload);
    std::cerr << "usage: cosmic-client-peer echo|pub|sub --segment SEGMENT ... (see the source)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "cosmic-client-peer: " << e.what() << "\n";
    return 2;
  }
}

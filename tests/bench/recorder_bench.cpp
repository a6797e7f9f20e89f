// cosmic_recorder_bench: what recording costs per event (issue 37, item 6), without the networks.
//
//   BM_RecordEvents      offer() of 200,000 64-byte events (the payload of cosmic-bench-peer) into a
//                        recording Recorder, then stop(): the CPU of the whole process (the offering
//                        thread and the writer thread) per event, as scripts/bench counts cosmicd's.
//   BM_RecordOffer       offer() alone, on the calling thread, while the writer empties the queue
//                        (the thread waits, untimed, when the queue is half full: every offer copies).
//   BM_McapWriteMessage/L  McapWriter::write_message with zstd chunks (level L) into a sink that keeps
//                        nothing: the writer thread's MCAP share per event.
//
// Files go to a temporary directory (TMPDIR or /tmp), removed afterwards.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/mcap_writer.hpp"
#include "cosmic/recorder.hpp"

namespace {

using namespace cosmic;
namespace fs = std::filesystem;

constexpr std::size_t kPayloadBytes = 64;
constexpr std::size_t kEventsPerRun = 200'000;

class QuietLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

// cosmic-bench-peer's payload: a stamp, the index, then (index + i) & 0xff.
void fill_payload(std::vector<std::uint8_t>& payload, std::uint32_t index, std::int64_t stamp) {
  std::memcpy(payload.data(), &stamp, 8);
  std::memcpy(payload.data() + 8, &index, 4);
  std::memset(payload.data() + 12, 0, 4);
  for (std::size_t i = 16; i < payload.size(); ++i) payload[i] = static_cast<std::uint8_t>((index + i) & 0xff);
}

Nanos steady_now() { return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()); }

// A recorder writing every event of one untyped channel into a directory of its own.
struct RecordingRig {
  fs::path dir = fs::path(std::getenv("TMPDIR") != nullptr ? std::getenv("TMPDIR") : "/tmp") /
                 ("cosmic-recorder-bench-" + std::to_string(::getpid()));
  QuietLogger log;
  std::unique_ptr<Recorder> recorder;

  RecordingRig() {
    fs::remove_all(dir);
    RecordingSpec spec;
    spec.directory = dir.string();
    spec.memory = 64u << 20;  // scripts/bench's
    recorder = std::make_unique<Recorder>(spec, "bench", log);
    RecordedChannel channel;
    channel.id = 1;
    channel.name = "down";
    channel.metadata = {{"subject", "0xb002"}, {"class", "nrt"}};
    std::vector<RecordedChannel> channels;
    channels.push_back(std::move(channel));
    recorder->set_channels(std::move(channels));
    recorder->set_segment_names({"dds", "lcm"});
  }
  ~RecordingRig() {
    recorder.reset();
    fs::remove_all(dir);
  }
};

void BM_RecordEvents(benchmark::State& state) {
  RecordingRig rig;
  std::vector<std::uint8_t> payload(kPayloadBytes);
  EventHeader header;
  header.origin = 0x5eed;
  std::uint32_t index = 0;
  std::uint64_t dropped = 0;
  for (auto _ : state) {
    if (!rig.recorder->start()) {
      state.SkipWithError("the recorder did not start");
      break;
    }
    for (std::size_t n = 0; n < kEventsPerRun; ++n) {
      const Nanos now = steady_now();
      fill_payload(payload, ++index, now.count());
      header.sequence = index;
      header.created_ns = now.count();
      rig.recorder->offer(1, 0, header, now, payload);
    }
    rig.recorder->stop();  // the writer drains the queue and finishes the file
    dropped = rig.recorder->status().dropped_full;
  }
  const RecorderStatus status = rig.recorder->status();
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kEventsPerRun));
  state.counters["written"] = static_cast<double>(status.messages);
  state.counters["dropped"] = static_cast<double>(dropped);
  state.counters["ratio"] =
      status.compressed > 0 ? static_cast<double>(status.uncompressed) / static_cast<double>(status.compressed) : 0;
}
BENCHMARK(BM_RecordEvents)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_RecordOffer(benchmark::State& state) {
  RecordingRig rig;
  if (!rig.recorder->start()) {
    state.SkipWithError("the recorder did not start");
    return;
  }
  const std::size_t half_queue = rig.recorder->status().queue_bytes / 2;
  std::vector<std::uint8_t> payload(kPayloadBytes);
  EventHeader header;
  header.origin = 0x5eed;
  std::uint32_t index = 0;
  for (auto _ : state) {
    const Nanos now = steady_now();
    fill_payload(payload, ++index, now.count());
    header.sequence = index;
    header.created_ns = now.count();
    rig.recorder->offer(1, 0, header, now, payload);
    // An offer that finds the queue full costs less than one that copies: past half full, wait
    // (untimed) for the writer.
    if (index % 4096 == 0 && rig.recorder->status().queued_bytes > half_queue) {
      state.PauseTiming();
      while (rig.recorder->status().queued_bytes > half_queue / 2) std::this_thread::yield();
      state.ResumeTiming();
    }
  }
  rig.recorder->stop();
  state.SetItemsProcessed(state.iterations());
  state.counters["dropped"] = static_cast<double>(rig.recorder->status().dropped_full);
}
BENCHMARK(BM_RecordOffer);

void BM_McapWriteMessage(benchmark::State& state) {
  std::uint64_t sunk = 0;
  McapWriterOptions options;
  options.zstd_level = static_cast<int>(state.range(0));
  auto writer = McapWriter::open(options, [&sunk](std::span<const std::uint8_t> bytes) -> Result<void> {
    sunk += bytes.size();
    return {};
  });
  if (!writer) {
    state.SkipWithError("the writer did not open");
    return;
  }
  const auto channel = writer.value().add_channel(0, "down", "x-cosmic-bytes", {{"segment", "dds"}});
  std::vector<std::uint8_t> payload(kPayloadBytes);
  std::uint32_t index = 0;
  std::int64_t t = 1'700'000'000'000'000'000;
  for (auto _ : state) {
    t += 7'000;
    fill_payload(payload, ++index, t);
    if (!writer.value().write_message(channel.value(), index, static_cast<std::uint64_t>(t),
                                      static_cast<std::uint64_t>(t - 3'000), payload)) {
      state.SkipWithError("write_message failed");
      break;
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["ratio"] = writer.value().compressed_bytes() > 0
                                ? static_cast<double>(writer.value().uncompressed_bytes()) /
                                      static_cast<double>(writer.value().compressed_bytes())
                                : 0;
}
BENCHMARK(BM_McapWriteMessage)->Arg(3)->Arg(1)->Arg(-1)->Arg(-3);

}  // namespace

BENCHMARK_MAIN();

// cosmic_admission_bench: Google Benchmark figures of admission at scale (issue 11). Prints
// figures; never a pass/fail target. Sets are generated deterministically (same set every run):
//
//   BM_AdmitBigSet             admit_all of 1,000 channels on one 1 Mbit/s CAN bus (CAN -> DDS,
//                              10 % HRT, 60 % SRT, 30 % NRT, periods 100 ms .. 5 s, about 50 %
//                              load) plus 10,000 IP channels (DDS <-> LCM): every channel bound
//                              one after the other, as cosmicd start and `cosmicctl check` do.
//   BM_BindIntoBigSet/kind     one more channel tried on top of that set (KnowledgeBase::probe:
//                              the full analysis a bind runs, without keeping it): kind 0 = a CAN
//                              channel of the highest priority (the whole bus re-examined), 1 =
//                              the lowest (itself only), 2 = an IP-only channel.
//   BM_CopyBigSet              copying the KnowledgeBase of that set (admission on a copy).
//   BM_CheckFile               `cosmicctl check` of that set as a YAML file, in process: load and
//                              validate the file, admit_all, render the text report.
//                              COSMIC_ADMISSION_YAML=PATH also leaves the file there, to time the
//                              real `cosmicctl check PATH`.
//   BM_OverloadedCanToCan/n    admit_all of n SRT channels from one 125 kbit/s CAN bus to
//                              another, 8 B every 10 ms (12.8 % each: the bus overloads after 5;
//                              SRT is degraded, not refused, so all stay bound and analysed), the
//                              shape issue 11 measured at 0.02 / 0.85 / 18 s for 25 / 50 / 100.
//   BM_LcmChannels/n           admit_all of n DDS -> LCM channels (issue 11: 0.45 / 1.8 / 7.1 s for
//                              1k / 2k / 4k before).
//   BM_ParseDbc/n              parse_dbc of an n-message DBC (issue 19; 500 keeps every id unique).
//   BM_AdmitWithDbcBackground  the 1,000 CAN channels of BM_AdmitBigSet on a bus whose background is
//                              a 500-message DBC: load the YAML and the DBC, admit_all (issue 19).
// A reload of that set by a running cosmicd is timed by tests/bench/reload_bench.sh.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "cosmic/config_loader.hpp"
#include "cosmic/dbc.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"

namespace {

using cosmic::ChannelClass;
using cosmic::ChannelSpec;
using cosmic::Config;
using cosmic::Nanos;
using cosmic::SegmentSpec;
using cosmic::SegmentType;

constexpr std::int64_t kMs = 1'000'000;

SegmentSpec can_bus(const std::string& name, const std::string& interface, std::uint64_t bitrate) {
  SegmentSpec s;
  s.name = name;
  s.type = SegmentType::can;
  s.can.interface = interface;
  s.can.bitrate = cosmic::BitRate{bitrate};
  s.can.data_bitrate = cosmic::BitRate{bitrate};
  return s;
}

SegmentSpec ip(const std::string& name, SegmentType type) {
  SegmentSpec s;
  s.name = name;
  s.type = type;
  s.bandwidth = cosmic::BitRate{1'000'000'000};
  s.latency_bound = Nanos(type == SegmentType::dds ? 1 * kMs : 5 * kMs);
  s.realtime = type == SegmentType::dds;
  s.reliability = type == SegmentType::dds ? cosmic::Reliability::reliable : cosmic::Reliability::best_effort;
  return s;
}

ChannelSpec channel(const std::string& name, std::uint64_t subject, ChannelClass cls, std::string from, std::string to,
                    std::uint64_t payload, std::int64_t period_ms, std::int64_t reaction_ms) {
  ChannelSpec c;
  c.name = name;
  c.subject = subject;
  c.cls = cls;
  c.payload = payload;
  c.period = Nanos(period_ms * kMs);
  if (cls != ChannelClass::nrt) c.reaction_time = Nanos(reaction_ms * kMs);
  c.omission_degree = 1;
  c.publishers = {std::move(from)};
  c.subscribers = {std::move(to)};
  return c;
}

Config base_config() {
  Config config;
  config.gateway.name = "bench";
  config.gateway.residence_bound = Nanos(kMs / 2);
  return config;
}

// 1,000 CAN channels on one bus and 10,000 IP channels.
Config big_config(std::size_t can_channels = 1000, std::size_t ip_channels = 10000) {
  Config config = base_config();
  config.segments = {can_bus("body-can", "vcan0", 1'000'000), ip("lan", SegmentType::dds), ip("viz", SegmentType::lcm)};
  constexpr std::int64_t kPeriods[] = {100, 200, 500, 1000, 2000, 5000};
  for (std::size_t i = 0; i < can_channels; ++i) {
    const ChannelClass cls = i % 10 == 0 ? ChannelClass::hrt : i % 10 < 7 ? ChannelClass::srt : ChannelClass::nrt;
    const std::int64_t period = kPeriods[(i * 7) % 6];
    config.channels.push_back(channel("can" + std::to_string(i), 0x100000 + i, cls, "body-can", "lan", 1 + (i * 5) % 8,
                                      period, period / 2 + static_cast<std::int64_t>(i % 37)));
  }
  for (std::size_t i = 0; i < ip_channels; ++i) {
    const ChannelClass cls = i % 3 == 0 ? ChannelClass::srt : ChannelClass::nrt;
    const bool up = i % 2 == 0;
    config.channels.push_back(channel("ip" + std::to_string(i), 0x200000 + i, cls, up ? "lan" : "viz",
                                      up ? "viz" : "lan", 64 + (i * 13) % 960, kPeriods[(i * 5) % 6],
                                      20 + static_cast<std::int64_t>(i % 50)));
  }
  return config;
}

Config overloaded_can_to_can(std::size_t n) {
  Config config = base_config();
  config.segments = {can_bus("can-a", "vcan0", 125'000), can_bus("can-b", "vcan1", 125'000)};
  for (std::size_t i = 0; i < n; ++i) {
    config.channels.push_back(channel("c" + std::to_string(i), 0x300000 + i, ChannelClass::srt, "can-a", "can-b", 8, 10,
                                      20 + static_cast<std::int64_t>(i % 30)));
  }
  return config;
}

Config lcm_channels(std::size_t n) {
  Config config = base_config();
  config.segments = {ip("lan", SegmentType::dds), ip("viz", SegmentType::lcm)};
  for (std::size_t i = 0; i < n; ++i) {
    config.channels.push_back(
        channel("l" + std::to_string(i), 0x400000 + i, ChannelClass::nrt, "lan", "viz", 256, 1000, 0));
  }
  return config;
}

void report_verdicts(benchmark::State& state, const cosmic::AdmissionReport& report) {
  std::size_t rejected = 0;
  for (const auto& c : report.channels) rejected += c.verdict == cosmic::Verdict::rejected ? 1 : 0;
  state.counters["channels"] = static_cast<double>(report.channels.size());
  state.counters["rejected"] = static_cast<double>(rejected);
}

void admit_repeatedly(benchmark::State& state, const Config& config) {
  cosmic::AdmissionReport report;
  for (auto _ : state) {
    report = cosmic::admit_all(config);
    benchmark::DoNotOptimize(report);
  }
  report_verdicts(state, report);
}

void BM_AdmitBigSet(benchmark::State& state) { admit_repeatedly(state, big_config()); }
BENCHMARK(BM_AdmitBigSet)->Unit(benchmark::kMillisecond)->Iterations(3);

cosmic::KnowledgeBase big_knowledge_base() {
  const Config config = big_config();
  cosmic::KnowledgeBase kb(config.gateway, config.segments);
  for (const auto& c : config.channels) kb.bind(c);
  return kb;
}

void BM_BindIntoBigSet(benchmark::State& state) {
  const cosmic::KnowledgeBase kb = big_knowledge_base();
  const ChannelSpec newcomer =
      state.range(0) == 0   ? channel("first", 1, ChannelClass::hrt, "body-can", "lan", 8, 1000, 3)
      : state.range(0) == 1 ? channel("last", 2, ChannelClass::nrt, "body-can", "lan", 1, 5000, 0)
                            : channel("ip", 3, ChannelClass::srt, "lan", "viz", 128, 100, 50);
  cosmic::ChannelReport report;
  for (auto _ : state) {
    report = kb.probe(newcomer);
    benchmark::DoNotOptimize(report);
  }
  state.counters["bound_channels"] = static_cast<double>(kb.bound_channels().size());
  state.counters["newcomer_rejected"] = report.verdict == cosmic::Verdict::rejected ? 1 : 0;
}
BENCHMARK(BM_BindIntoBigSet)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_CopyBigSet(benchmark::State& state) {
  const cosmic::KnowledgeBase kb = big_knowledge_base();
  for (auto _ : state) {
    cosmic::KnowledgeBase copy = kb;
    benchmark::DoNotOptimize(copy);
  }
}
BENCHMARK(BM_CopyBigSet)->Unit(benchmark::kMillisecond);

std::string duration(const std::optional<Nanos>& value) { return std::to_string(value->count() / 1000) + "us"; }

// The set as the YAML a user would write (DESIGN.md section 3).
std::string to_yaml(const Config& config) {
  std::ostringstream out;
  out << "gateway:\n  name: " << config.gateway.name
      << "\n  can_node_id: 1\n  residence_bound: " << duration(config.gateway.residence_bound) << "\nsegments:\n";
  for (const auto& s : config.segments) {
    out << "  - name: " << s.name << "\n    type: " << cosmic::to_string(s.type) << "\n";
    if (s.type == SegmentType::can) {
      out << "    interface: " << s.can.interface << "\n    bitrate: " << s.can.bitrate.bits_per_second / 1000
          << "kbit/s\n";
    } else {
      out << "    latency_bound: " << duration(s.latency_bound)
          << "\n    bandwidth: " << s.bandwidth.bits_per_second / 1000 << "kbit/s\n";
      out << (s.type == SegmentType::dds ? "    domain: 0\n    realtime: true\n"
                                         : "    url: udpm://239.255.76.67:7667?ttl=0\n");
    }
  }
  out << "channels:\n";
  for (const auto& c : config.channels) {
    char subject[32];
    std::snprintf(subject, sizeof subject, "0x%016llx", static_cast<unsigned long long>(c.subject));
    out << "  - name: " << c.name << "\n    subject: " << subject << "\n    class: " << cosmic::to_string(c.cls)
        << "\n    period: " << duration(c.period) << "\n";
    if (c.reaction_time) out << "    reaction_time: " << duration(c.reaction_time) << "\n";
    out << "    omission_degree: " << c.omission_degree << "\n    payload: " << c.payload << "B\n    publishers: ["
        << c.publishers[0] << "]\n    subscribers: [" << c.subscribers[0] << "]\n";
  }
  return out.str();
}

void BM_CheckFile(benchmark::State& state) {
  const char* keep = std::getenv("COSMIC_ADMISSION_YAML");
  const std::string path = keep ? keep : "/tmp/cosmic_admission_bench_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << to_yaml(big_config());
  std::size_t bytes = 0;
  for (auto _ : state) {
    const auto loaded = cosmic::load_config_file(path);
    if (!loaded.ok()) {
      state.SkipWithError((loaded.errors.front().to_string()).c_str());
      break;
    }
    const std::string text = cosmic::render_text(cosmic::admit_all(loaded.config));
    bytes = text.size();
  }
  state.counters["report_bytes"] = static_cast<double>(bytes);
  if (!keep) std::remove(path.c_str());
}
BENCHMARK(BM_CheckFile)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_OverloadedCanToCan(benchmark::State& state) {
  admit_repeatedly(state, overloaded_can_to_can(static_cast<std::size_t>(state.range(0))));
}
BENCHMARK(BM_OverloadedCanToCan)->Arg(25)->Arg(50)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

void BM_LcmChannels(benchmark::State& state) {
  admit_repeatedly(state, lcm_channels(static_cast<std::size_t>(state.range(0))));
}
BENCHMARK(BM_LcmChannels)->Arg(1000)->Arg(2000)->Arg(4000)->Arg(10000)->Unit(benchmark::kMillisecond);

// A body bus's DBC of n messages (issue 19): identifiers spread over the standard and extended
// ranges (every fourth extended), 1..8 bytes, cycle times 100 ms .. 10 s (about 17 % of 1 Mbit/s).
std::string body_dbc(std::size_t n) {
  constexpr std::int64_t kCycles[] = {100, 200, 500, 1000, 2000, 5000, 10000};
  std::ostringstream out;
  out << "VERSION \"\"\n\nNS_ :\n\tBA_DEF_\n\nBS_:\n\nBU_: Ecu\n\n";
  for (std::size_t i = 0; i < n; ++i) {
    const bool extended = i % 4 == 3;
    const std::uint64_t id = extended ? 0x80000000ull | (0x10000000ull + i * 977) : 0x080 + (i * 3) % 0x700;
    out << "BO_ " << id << " Msg" << i << ": " << 1 + i % 8 << " Ecu\n SG_ S" << i
        << " : 0|8@1+ (1,0) [0|255] \"\" Ecu\n\n";
  }
  out << "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 65535;\nBA_DEF_DEF_ \"GenMsgCycleTime\" 0;\n";
  for (std::size_t i = 0; i < n; ++i) {
    const bool extended = i % 4 == 3;
    const std::uint64_t id = extended ? 0x80000000ull | (0x10000000ull + i * 977) : 0x080 + (i * 3) % 0x700;
    out << "BA_ \"GenMsgCycleTime\" BO_ " << id << " " << kCycles[i % 7] << ";\n";
  }
  return out.str();
}

void BM_ParseDbc(benchmark::State& state) {
  const std::string text = body_dbc(static_cast<std::size_t>(state.range(0)));
  std::size_t messages = 0;
  for (auto _ : state) {
    const cosmic::DbcFile dbc = cosmic::parse_dbc(text);
    messages = dbc.messages.size();
    benchmark::DoNotOptimize(messages);
  }
  state.counters["messages"] = static_cast<double>(messages);
  state.counters["bytes"] = static_cast<double>(text.size());
}
BENCHMARK(BM_ParseDbc)->Arg(500)->Unit(benchmark::kMillisecond);

// BM_AdmitBigSet's 1,000 CAN channels on a bus that also carries a 500-message DBC's frames, from the
// YAML and DBC files on disk as `cosmicctl check` reads them.
void BM_AdmitWithDbcBackground(benchmark::State& state) {
  const std::string dir = "/tmp/cosmic_admission_bench_dbc_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/body.dbc") << body_dbc(500);
  std::string yaml = to_yaml(big_config(1000, 0));
  const std::string bus = "    bitrate: 1000kbit/s\n";
  yaml.insert(yaml.find(bus) + bus.size(), "    background: {dbc: body.dbc}\n");
  std::ofstream(dir + "/gw.yaml") << yaml;
  cosmic::AdmissionReport report;
  for (auto _ : state) {
    const auto loaded = cosmic::load_config_file(dir + "/gw.yaml");
    if (!loaded.ok()) {
      state.SkipWithError(loaded.errors.front().to_string().c_str());
      break;
    }
    report = cosmic::admit_all(loaded.config);
  }
  report_verdicts(state, report);
  if (!report.segments.empty()) {
    state.counters["background_frames"] = static_cast<double>(report.segments[0].background_frames);
    state.counters["background_load"] = report.segments[0].background;
    state.counters["bus_load"] = report.segments[0].utilization;
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_AdmitWithDbcBackground)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

// `cosmic_admission_bench --write-config PATH` only writes the big set (BM_AdmitBigSet's) as YAML,
// for tests/bench/reload_bench.sh to run cosmicd on.
int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--write-config") {
    std::ofstream out(argv[2]);
    out << to_yaml(big_config());
    return out.good() ? 0 : 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

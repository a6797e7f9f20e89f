// gateway.realtime and the DDS segment key `shared_memory` (docs/yaml-reference.md): what is
// accepted, and every mistake with its location and key path.
#include <gtest/gtest.h>

#include <thread>

#include "config_test_support.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

std::string document(const std::string& realtime, const std::string& dds_extra = "") {
  return "gateway:\n  name: gw1\n" + realtime +
         "segments:\n"
         "  - {name: lan, type: dds, domain: 3" +
         dds_extra +
         "}\n"
         "channels: []\n";
}

const unsigned kCpus = std::max(1u, std::thread::hardware_concurrency());

TEST(RealtimeConfig, PrioritiesAndOneListOfCpusForEveryThread) {
  const ConfigResult r = parse_config(
      document("  realtime: {priorities: {hrt: 80, srt: 60, receive: 10}, cpus: [0], lock_memory: true}\n"), "g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  const RealtimeSpec& rt = r.config.gateway.realtime;
  EXPECT_EQ(rt.hrt_priority, 80);
  EXPECT_EQ(rt.srt_priority, 60);
  EXPECT_EQ(rt.nrt_priority, 0);
  EXPECT_EQ(rt.receive_priority, 10);
  EXPECT_TRUE(rt.lock_memory);
  const std::vector<int> zero{0};
  EXPECT_EQ(rt.cpus, (CpuPlacement{zero, zero, zero, zero, zero}));
  const ConfigResult none = parse_config(document(""), "g.yaml");
  ASSERT_TRUE(none.ok()) << test::errors_text(none);
  EXPECT_FALSE(none.config.gateway.realtime.requested());
  EXPECT_FALSE(none.config.gateway.realtime.cpus.any());
}

TEST(RealtimeConfig, CpusByKindOfThread) {
  const int last = static_cast<int>(kCpus) - 1;
  const std::string text =
      "  realtime: {cpus: {hrt: [" + std::to_string(last) + "], nrt: [0], receive: [0], other: [0]}}\n";
  const ConfigResult r = parse_config(document(text), "g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  const CpuPlacement& c = r.config.gateway.realtime.cpus;
  EXPECT_EQ(c.hrt, std::vector<int>{last});
  EXPECT_TRUE(c.srt.empty()) << "a kind not named is left to other";
  EXPECT_EQ(c.of(ChannelClass::nrt), std::vector<int>{0});
  EXPECT_EQ(c.of(ChannelClass::hrt), std::vector<int>{last});
  EXPECT_EQ(c.receive, std::vector<int>{0});
  EXPECT_EQ(c.other, std::vector<int>{0});
  EXPECT_TRUE(r.config.gateway.realtime.requested());
}

TEST(RealtimeConfig, SharedMemoryByClass) {
  const ConfigResult defaults = parse_config(document(""), "g.yaml");
  ASSERT_TRUE(defaults.ok()) << test::errors_text(defaults);
  EXPECT_EQ(defaults.config.segments[0].dds.shared_memory, (std::array<bool, 3>{false, true, true}))
      << "HRT over UDP alone, the others with shared memory";
  const ConfigResult all = parse_config(document("", ", shared_memory: [hrt, srt, nrt]"), "g.yaml");
  ASSERT_TRUE(all.ok()) << test::errors_text(all);
  EXPECT_EQ(all.config.segments[0].dds.shared_memory, (std::array<bool, 3>{true, true, true}));
  const ConfigResult none = parse_config(document("", ", shared_memory: []"), "g.yaml");
  ASSERT_TRUE(none.ok()) << test::errors_text(none);
  EXPECT_EQ(none.config.segments[0].dds.shared_memory, (std::array<bool, 3>{false, false, false}));
}

TEST(RealtimeConfig, EveryMistakeIsReportedWithItsPlace) {
  struct Case {
    std::string realtime;
    std::string dds_extra;
    std::string expected;
  };
  const std::string missing_cpu = std::to_string(kCpus);
  const std::vector<Case> cases = {
      {"  realtime: {cpus: [" + missing_cpu + "]}\n", "",
       "gateway.realtime.cpus[0]: CPU " + missing_cpu + " does not exist on this machine"},
      {"  realtime: {cpus: {hrt: [" + missing_cpu + "]}}\n", "",
       "gateway.realtime.cpus.hrt[0]: CPU " + missing_cpu + " does not exist"},
      {"  realtime: {cpus: {fast: [0]}}\n", "", "gateway.realtime.cpus.fast"},
      {"  realtime: {cpus: 1}\n", "",
       "g.yaml:3:20: gateway.realtime.cpus: expected a list of CPUs or a map of them by thread kind"},
      {"  realtime: {cpus: {other: 0}}\n", "", "gateway.realtime.cpus.other"},
      {"  realtime: {priorities: {hrt: 10, srt: 60}}\n", "",
       "gateway.realtime.priorities: class priorities are out of order"},
      {"", ", shared_memory: [hrt, fast]", "segments[0].shared_memory[1]"},
      {"", ", shared_memory: hrt", "segments[0].shared_memory"},
  };
  for (const Case& c : cases) {
    const ConfigResult r = parse_config(document(c.realtime, c.dds_extra), "g.yaml");
    test::expect_refused_with(r, c.expected);
  }
}

}  // namespace
}  // namespace cosmic

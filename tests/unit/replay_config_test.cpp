// A replay segment's configuration (`type: replay`, docs/yaml-reference.md): the recording read at
// load (each selected channel's events and tightest spacing), a relative file anchored at the
// configuration, and every mistake with its place: no file, a file that is not a recording, a
// selection matching nothing recorded, a speed out of range, a native binding or a component on it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "config_test_support.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/mcap_writer.hpp"

namespace cosmic {
namespace {

namespace fs = std::filesystem;

class ReplayConfig : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("replay_config_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    // obstacle at 0, 10, 18, 30 ms (tightest 8 ms); drive at 5, 25 ms.
    std::vector<std::uint8_t> bytes;
    auto writer = McapWriter::open({}, [&](std::span<const std::uint8_t> b) -> Result<void> {
      bytes.insert(bytes.end(), b.begin(), b.end());
      return {};
    });
    ASSERT_TRUE(writer);
    const auto obstacle = writer.value().add_channel(0, "obstacle", "x-cosmic-bytes");
    const auto drive = writer.value().add_channel(0, "drive", "x-cosmic-bytes");
    const std::vector<std::uint8_t> data{1, 2, 3, 4};
    const std::pair<std::uint16_t, std::uint64_t> messages[] = {{obstacle.value(), 0},  {drive.value(), 5},
                                                                {obstacle.value(), 10}, {obstacle.value(), 18},
                                                                {drive.value(), 25},    {obstacle.value(), 30}};
    std::uint32_t n = 0;
    for (const auto& [channel, ms] : messages)
      ASSERT_TRUE(writer.value().write_message(channel, ++n, 1'000'000'000'000 + ms * 1'000'000, 0, data));
    ASSERT_TRUE(writer.value().finish());
    std::ofstream(dir_ / "run.mcap", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(dir_ / "bogus.mcap") << "not a recording";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string file() const { return (dir_ / "g.yaml").string(); }

  static std::string document(const std::string& replay, const std::string& extra = "") {
    return "segments:\n"
           "  - {name: viz, type: lcm, url: \"udpm://239.255.76.67:7667?ttl=0\"}\n"
           "  - " +
           replay +
           "\n"
           "channels:\n"
           "  - {name: obstacle, subject: 0x10, class: nrt, period: 5ms, publishers: [rec], subscribers: [viz]}\n" +
           extra;
  }

  fs::path dir_;
};

TEST_F(ReplayConfig, TheRecordingIsReadAtLoadAndARelativeFileIsTheConfigurations) {
  const ConfigResult r = parse_config(
      document("{name: rec, type: replay, file: run.mcap, speed: 2, loop: true, start_offset: 10ms}"), file());
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  const SegmentSpec& rec = r.config.segments[1];
  EXPECT_EQ(rec.type, SegmentType::replay);
  EXPECT_EQ(rec.replay.file, (dir_ / "run.mcap").string());
  EXPECT_EQ(rec.replay.speed, 2.0);
  EXPECT_TRUE(rec.replay.loop);
  EXPECT_EQ(rec.replay.start_offset, Nanos(10'000'000));
  EXPECT_EQ(rec.latency_bound, Nanos(1'000'000));
  ASSERT_EQ(rec.replay.streams.size(), 2u);
  EXPECT_EQ(rec.replay.streams[0], (ReplayStream{"obstacle", 4, Nanos(8'000'000)}));
  EXPECT_EQ(rec.replay.streams[1], (ReplayStream{"drive", 2, Nanos(20'000'000)}));
  EXPECT_NE(rec.replay.content_hash, 0u);
  const ConfigResult selected =
      parse_config(document("{name: rec, type: replay, file: run.mcap, channels: ['obst*']}"), file());
  ASSERT_TRUE(selected.ok()) << test::errors_text(selected);
  ASSERT_EQ(selected.config.segments[1].replay.streams.size(), 1u);
  EXPECT_EQ(selected.config.segments[1].replay.streams[0].channel, "obstacle");
}

// An hrt channel needs a real-time publisher segment: a replay is one only when declared so.
TEST_F(ReplayConfig, AnHrtChannelIsReplayedOnlyFromAReplayDeclaredRealTime) {
  for (const bool realtime : {false, true}) {
    const ConfigResult r = parse_config(
        std::string("segments:\n"
                    "  - {name: viz, type: lcm, url: \"udpm://239.255.76.67:7667?ttl=0\", realtime: true}\n"
                    "  - {name: rec, type: replay, file: run.mcap, channels: [obstacle], realtime: ") +
            (realtime ? "true" : "false") +
            "}\n"
            "channels:\n"
            "  - {name: obstacle, subject: 0x10, class: hrt, period: 5ms, reaction_time: 40ms, omission_degree: 1,\n"
            "     publishers: [rec], subscribers: [viz]}\n",
        file());
    ASSERT_TRUE(r.ok()) << test::errors_text(r);
    EXPECT_EQ(r.config.segments[1].realtime, realtime);
    const AdmissionReport report = admit_all(r.config);
    const ChannelReport* verdict = report.find("obstacle");
    ASSERT_NE(verdict, nullptr);
    std::string reasons;
    for (const auto& reason : verdict->reasons) reasons += reason + "; ";
    EXPECT_EQ(verdict->verdict, realtime ? Verdict::bound : Verdict::rejected) << reasons;
    EXPECT_EQ(reasons.find("hrt on rec, which declares no real-time guarantee") != std::string::npos, !realtime)
        << reasons;
  }
}

TEST_F(ReplayConfig, EveryMistakeIsReportedWithItsPlace) {
  struct Case {
    std::string replay;
    std::string extra;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"{name: rec, type: replay}", "", "segments[1].file: missing required key 'file'"},
      {"{name: rec, type: replay, file: missing.mcap}", "",
       "segments[1].file: cannot open " + (dir_ / "missing.mcap").string()},
      {"{name: rec, type: replay, file: bogus.mcap}", "",
       "segments[1].file: " + (dir_ / "bogus.mcap").string() + " is not a readable recording"},
      {"{name: rec, type: replay, file: run.mcap, channels: [lidar]}", "", "holds no event of the selected channels"},
      {"{name: rec, type: replay, file: run.mcap, speed: 0}", "", "segments[1].speed: speed out of range"},
      {"{name: rec, type: replay, file: run.mcap, speed: 5000}", "", "segments[1].speed: speed out of range"},
      {"{name: rec, type: replay, file: run.mcap, url: x}", "", "segments[1].url"},
      {"{name: rec, type: replay, file: run.mcap, start_offset: soon}", "", "segments[1].start_offset"},
      {"{name: rec, type: replay, file: run.mcap, start_offset: 31ms}", "",
       "segments[1].start_offset: start_offset beyond the recording (at most 30 ms"},
      {"{name: rec, type: replay, file: run.mcap, realtime: maybe}", "", "segments[1].realtime"},
      {"{name: rec, type: replay, file: run.mcap}",
       "components:\n  - {name: lidar, segment: rec, publishes: [obstacle]}\n",
       "segment 'rec' is a replay: it publishes a recording, no component lives there"},
  };
  for (const Case& c : cases) {
    const ConfigResult r = parse_config(document(c.replay, c.extra), file());
    test::expect_refused_with(r, c.expected);
  }
}

}  // namespace
}  // namespace cosmic

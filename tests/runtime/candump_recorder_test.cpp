// CAN logs (cosmic/candump_recorder.hpp) over real files in a temporary directory: frames handed to
// a segment's tap (as a CAN adapter hands them: struct can_frame / canfd_frame bytes, received and
// sent) come out as candump -l lines of that segment's interface, in order, one file per segment
// named GATEWAY-SEGMENT-YYYYMMDD-HHMMSS-N.log; nothing is logged before start(), after stop() or by
// a tap of a segment not listed; every start opens new files; files rotate by size, each holding
// whole lines; what the queue cannot take is counted dropped, never lost silently.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "cosmic/candump_log.hpp"
#include "cosmic/candump_recorder.hpp"

namespace cosmic {
namespace {

namespace fs = std::filesystem;

class CandumpTestLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view) override {}
};

constexpr std::int64_t kT0 = 1'700'000'000'000'000'000;

// Hands `tap` the frame `text` (e.g. "123#DEADBEEF") as the CAN adapter would, at kT0 + `us` µs.
void feed(WireTap& tap, const std::string& text, std::int64_t us, WireDirection direction = WireDirection::received) {
  const auto frame = parse_candump_frame(text);
  ASSERT_TRUE(frame) << text;
  std::array<std::uint8_t, kCanFdMtu> wire{};
  const std::size_t size = candump_frame_to_wire(frame.value(), wire);
  tap.on_wire(WireUnit{direction, Nanos(0), kT0 + us * 1000, std::span(wire).first(size)});
}

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

class CandumpRecorderTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("candump_test_" + std::to_string(::getpid()) + "_" +
                                           testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    spec_.directory = (dir_ / "logs").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The log files in the directory, oldest (lowest N) first.
  std::vector<fs::path> files() const {
    std::vector<std::pair<int, fs::path>> numbered;
    const std::regex name(R"(gw-([a-z0-9]+)-\d{8}-\d{6}-(\d+)\.log)");
    for (const auto& entry : fs::directory_iterator(spec_.directory)) {
      std::smatch m;
      const std::string file = entry.path().filename().string();
      EXPECT_TRUE(std::regex_match(file, m, name)) << file;
      numbered.emplace_back(std::stoi(m[2].str()), entry.path());
    }
    std::sort(numbered.begin(), numbered.end());
    std::vector<fs::path> out;
    for (auto& [n, path] : numbered) out.push_back(path);
    return out;
  }

  fs::path dir_;
  RecordingSpec spec_;
  CandumpTestLogger log_;
};

TEST_F(CandumpRecorderTest, FramesThroughTheTapBecomeCandumpLines) {
  auto body = std::make_shared<CandumpTap>();
  auto chassis = std::make_shared<CandumpTap>();
  auto unlisted = std::make_shared<CandumpTap>();
  CandumpRecorder recorder(spec_, "gw", log_);
  feed(*body, "111#01", 0);  // before start: nothing
  ASSERT_TRUE(recorder.start({{"body", "vcan0", body}, {"chassis", "vcan1", chassis}}));
  feed(*body, "123#DEADBEEF", 1);
  feed(*body, "00A0412C#R", 2, WireDirection::sent);
  feed(*chassis, "1ABCDEF0##1112233445566778899AABBCC", 3);
  feed(*unlisted, "222#02", 4);
  feed(*body, "7FF#", 5);
  EXPECT_TRUE(recorder.status().recording);
  recorder.stop();
  feed(*body, "333#03", 6);  // after stop: nothing

  const auto logs = files();
  ASSERT_EQ(logs.size(), 2u);
  const fs::path body_log = logs[0].filename().string().find("-body-") != std::string::npos ? logs[0] : logs[1];
  const fs::path chassis_log = body_log == logs[0] ? logs[1] : logs[0];
  EXPECT_EQ(lines_of(body_log),
            (std::vector<std::string>{"(1700000000.000001) vcan0 123#DEADBEEF", "(1700000000.000002) vcan0 00A0412C#R",
                                      "(1700000000.000005) vcan0 7FF#"}));
  EXPECT_EQ(lines_of(chassis_log),
            (std::vector<std::string>{"(1700000000.000003) vcan1 1ABCDEF0##1112233445566778899AABBCC"}));
  const CandumpStatus s = recorder.status();
  EXPECT_FALSE(s.recording);
  EXPECT_TRUE(s.files_open.empty());
  EXPECT_EQ(s.files, 2u);
  EXPECT_EQ(s.lines, 4u);
  EXPECT_EQ(s.dropped_full + s.dropped_failed, 0u);
  // Every line reads back as candump -l's.
  for (const auto& line : lines_of(body_log)) EXPECT_TRUE(parse_candump_line(line)) << line;
}

TEST_F(CandumpRecorderTest, EveryStartOpensNewFiles) {
  auto tap = std::make_shared<CandumpTap>();
  CandumpRecorder recorder(spec_, "gw", log_);
  ASSERT_TRUE(recorder.start({{"body", "vcan0", tap}}));
  feed(*tap, "001#01", 1);
  recorder.stop();
  ASSERT_TRUE(recorder.start({{"body", "vcan0", tap}}));
  EXPECT_EQ(recorder.status().files_open.size(), 1u);
  feed(*tap, "002#02", 2);
  recorder.stop();
  const auto logs = files();
  ASSERT_EQ(logs.size(), 2u);
  EXPECT_EQ(lines_of(logs[0]), std::vector<std::string>{"(1700000000.000001) vcan0 001#01"});
  EXPECT_EQ(lines_of(logs[1]), std::vector<std::string>{"(1700000000.000002) vcan0 002#02"});
}

TEST_F(CandumpRecorderTest, RotatesBySizeWithWholeLines) {
  spec_.rotate_size = 100;  // two or three lines per file
  auto tap = std::make_shared<CandumpTap>();
  CandumpRecorder recorder(spec_, "gw", log_);
  ASSERT_TRUE(recorder.start({{"body", "vcan0", tap}}));
  std::vector<std::string> sent;
  for (int i = 0; i < 30; ++i) {
    char text[48];
    std::snprintf(text, sizeof text, "%03X#00112233445566%02X", i, i);
    feed(*tap, text, i);
    sent.push_back("(1700000000." + std::string(6 - std::to_string(i).size(), '0') + std::to_string(i) + ") vcan0 " +
                   text);
  }
  recorder.stop();
  const auto logs = files();
  ASSERT_GE(logs.size(), 10u);
  std::vector<std::string> all;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const auto size = fs::file_size(logs[i]);
    // A file ends with the line that takes it to the limit; only the last may stay below it.
    EXPECT_LT(size, 100u + kCandumpMaxLine) << logs[i];
    if (i + 1 < logs.size()) {
      EXPECT_GE(size, 100u) << logs[i];
    }
    for (auto& line : lines_of(logs[i])) all.push_back(std::move(line));
  }
  EXPECT_EQ(all, sent);
  EXPECT_EQ(recorder.status().files, logs.size());
}

TEST_F(CandumpRecorderTest, WhatTheQueueCannotTakeIsCountedDropped) {
  spec_.memory = 16 * 1024;  // a 4 KiB queue: about forty CAN FD frames
  auto tap = std::make_shared<CandumpTap>();
  CandumpRecorder recorder(spec_, "gw", log_);
  ASSERT_TRUE(recorder.start({{"body", "vcan0", tap}}));
  // Longer than the queue takes at all: dropped, whatever the writer does meanwhile.
  std::vector<std::uint8_t> huge(4096);
  tap->on_wire(WireUnit{WireDirection::received, Nanos(0), kT0, huge});
  EXPECT_EQ(recorder.status().dropped_full, 1u);
  const std::string fd_frame = "123##0" + std::string(128, 'A');
  constexpr int kOffered = 2000;
  for (int i = 0; i < kOffered; ++i) feed(*tap, fd_frame, i);
  recorder.stop();
  const CandumpStatus s = recorder.status();
  EXPECT_GT(s.dropped_full, 1u);  // two thousand frames at once do not fit in forty frames' room
  EXPECT_EQ(s.lines + s.dropped_full - 1, static_cast<std::uint64_t>(kOffered));
  EXPECT_EQ(lines_of(files().at(0)).size(), s.lines);
}

TEST_F(CandumpRecorderTest, AStartThatCannotOpenItsFilesLogsNothing) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "logs") << "a file where the directory should be";
  auto tap = std::make_shared<CandumpTap>();
  CandumpRecorder recorder(spec_, "gw", log_);
  const auto started = recorder.start({{"body", "vcan0", tap}});
  ASSERT_FALSE(started);
  EXPECT_NE(started.error().text.find(spec_.directory), std::string::npos) << started.error().text;
  feed(*tap, "123#01", 1);
  EXPECT_FALSE(recorder.status().recording);
  EXPECT_EQ(recorder.status().dropped_full, 0u);
}

}  // namespace
}  // namespace cosmic

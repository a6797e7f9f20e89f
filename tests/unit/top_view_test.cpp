// cosmicctl top's frames (daemon/cosmicctl/top_view.cpp), a pure function of the daemon's answers.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "top_view.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;

TopSample sample(const std::string& verdict, std::uint64_t failed) {  // counts as parsed: unsigned
  TopSample s;
  s.status = Json::parse(R"({"ok":true,"gateway":{"name":"gw","id":"00000000000000aa","uptime_s":2.0},
    "segments":{"total":0,"up":0},"channels":{"bound":0,"degraded":0,"violated":0},
    "router":{"queued":0,"progress":0}})");
  s.status["channels"]["failed"] = failed;
  s.status["channels"]["bound"] = 1 - failed;
  s.segments = Json::parse(R"({"ok":true,"segments":[]})");
  s.channels = Json::parse(R"({"ok":true,"channels":[{"name":"speed","class":"nrt","runtime_state":"bound",
    "segments":[{"segment":"lan","role":"publisher","rx":0,"tx":0,"dropped":{"expired":0}}]}]})");
  s.channels["channels"][0]["verdict"] = verdict;
  s.taken = std::chrono::steady_clock::now();
  return s;
}

const TopLine& row_of(const std::vector<TopLine>& frame, const std::string& channel) {
  for (const auto& line : frame) {
    if (line.text.rfind(channel + " ", 0) == 0) return line;
  }
  static const TopLine none;
  ADD_FAILURE() << "no row for " << channel;
  return none;
}

// Issue 9, item 10: a channel its transport refused is `failed` in top too, in red.
TEST(TopView, AChannelItsTransportRefusedIsFailedAndRed) {
  const auto frame = top_frame(sample("failed", 1), std::nullopt);
  ASSERT_FALSE(frame.empty());
  EXPECT_NE(frame[0].text.find("channels 0 bound, 0 degraded, 1 failed, 0 violated"), std::string::npos)
      << frame[0].text;
  EXPECT_TRUE(frame[0].alert);
  const TopLine& speed = row_of(frame, "speed");
  EXPECT_NE(speed.text.find(" failed "), std::string::npos) << speed.text;
  EXPECT_TRUE(speed.alert);
}

TEST(TopView, ABoundChannelShowsItsRuntimeState) {
  const auto frame = top_frame(sample("bound", 0), std::nullopt);
  ASSERT_FALSE(frame.empty());
  EXPECT_NE(frame[0].text.find("channels 1 bound, 0 degraded, 0 failed, 0 violated"), std::string::npos)
      << frame[0].text;
  EXPECT_FALSE(frame[0].alert);
  const TopLine& speed = row_of(frame, "speed");
  EXPECT_NE(speed.text.find(" bound "), std::string::npos) << speed.text;
  EXPECT_EQ(speed.text.find("failed"), std::string::npos) << speed.text;
  EXPECT_FALSE(speed.alert);
}

}  // namespace
}  // namespace cosmicctl

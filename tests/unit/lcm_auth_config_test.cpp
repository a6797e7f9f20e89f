// An LCM segment's `auth: {key_file, window}`: the key file as the loader reads it (only its
// owner may read it, hexadecimal digits), every refusal located at the key, and what admission
// makes of an authenticated hop (the trailer's bytes counted, raw messages refused).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cosmic/admission.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/report.hpp"

namespace cosmic {
namespace {

class LcmAuthConfig : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / ("lcm_auth_config_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string key_file(const std::string& name, const std::string& text, unsigned mode) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    ::chmod(path.c_str(), mode);
    return path.string();
  }

  // A robot with an authenticated LCM segment and one channel to a DDS segment; `auth` is the
  // value of the segment's auth key, `encoding` the channel's.
  ConfigResult load(const std::string& auth, const std::string& encoding = "envelope") {
    const std::string text =
        "segments:\n"
        "  - {name: dds, type: dds, domain: 3}\n"
        "  - name: lan\n"
        "    type: lcm\n"
        "    url: udpm://239.255.76.67:7667?ttl=0\n"
        "    auth: " +
        auth +
        "\n"
        "channels:\n"
        "  - {name: obstacle, subject: 0x10, class: srt, period: 10ms, reaction_time: 50ms, payload: 16B,\n"
        "     encoding: " +
        encoding + ", omission_degree: 1, publishers: [lan], subscribers: [dds]}\n";
    return parse_config(text, (dir_ / "gateway.yaml").string());
  }

  std::filesystem::path dir_;
};

const std::string kKey32 = "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n";

TEST_F(LcmAuthConfig, AKeyFileRelativeToTheConfigurationIsRead) {
  key_file("lan.key", kKey32, 0600);
  const ConfigResult result = load("{key_file: lan.key, window: 250ms}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const SegmentSpec& lan = *result.config.find_segment("lan");
  ASSERT_TRUE(lan.lcm.auth);
  EXPECT_EQ(lan.lcm.auth->key_file, (dir_ / "lan.key").string());
  ASSERT_EQ(lan.lcm.auth->key.size(), 32u);
  EXPECT_EQ(lan.lcm.auth->key.bytes()[31], 0x1f);
  EXPECT_EQ(lan.lcm.auth->window, std::chrono::milliseconds(250));
  EXPECT_NE(std::find(result.included_files.begin(), result.included_files.end(), (dir_ / "lan.key").string()),
            result.included_files.end());
}

TEST_F(LcmAuthConfig, TheWindowDefaultsToOneSecond) {
  key_file("lan.key", kKey32, 0400);
  const ConfigResult result = load("{key_file: lan.key}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  EXPECT_EQ(result.config.find_segment("lan")->lcm.auth->window, std::chrono::seconds(1));
}

// Each refusal: at the key_file value (line 6, after "    auth: {key_file: "), saying why.
TEST_F(LcmAuthConfig, KeyFilesThatCannotBeUsedAreRefusedAtTheKey) {
  key_file("open.key", kKey32, 0644);
  key_file("short.key", "00112233\n", 0600);
  key_file("text.key", "this is no key\n", 0600);
  const struct {
    std::string file;
    std::string message;
  } cases[] = {
      {"open.key", "group or others may read or write it (mode 0644; chmod 600 it)"},
      {"missing.key", "No such file or directory"},
      {"short.key", "holds no key: 4 bytes of key, fewer than 16"},
      {"text.key", "holds no key: byte 1 is not a hexadecimal digit"},
  };
  for (const auto& c : cases) {
    const ConfigResult result = load("{key_file: " + c.file + "}");
    ASSERT_EQ(result.errors.size(), 1u) << c.file;
    const ConfigError& e = result.errors.front();
    EXPECT_EQ(e.line, 6) << c.file;
    EXPECT_EQ(e.column, 22) << c.file;
    EXPECT_EQ(e.path, "segments[1].auth.key_file") << c.file;
    EXPECT_NE(e.message.find(c.message), std::string::npos) << e.to_string();
    EXPECT_EQ(e.message.find("this is no key"), std::string::npos) << "a key file's text is never quoted";
  }
}

TEST_F(LcmAuthConfig, KeysAcceptedDuringAKeyChangeAreReadAndCheckedLikeTheKey) {
  key_file("lan.key", kKey32, 0600);
  key_file("next.key", "ff" + kKey32.substr(2), 0600);
  key_file("open.key", kKey32, 0604);
  const ConfigResult result = load("{key_file: lan.key, accept_key_files: [next.key]}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const LcmAuthSpec& auth = *result.config.find_segment("lan")->lcm.auth;
  ASSERT_EQ(auth.accepted.size(), 1u);
  EXPECT_EQ(auth.accepted.front().bytes()[0], 0xff);
  EXPECT_EQ(auth.accepted_files.front(), (dir_ / "next.key").string());
  const ConfigResult open = load("{key_file: lan.key, accept_key_files: [next.key, open.key]}");
  ASSERT_EQ(open.errors.size(), 1u);
  EXPECT_EQ(open.errors.front().path, "segments[1].auth.accept_key_files[1]");
  EXPECT_NE(open.errors.front().message.find("group or others may read or write it"), std::string::npos);
}

TEST_F(LcmAuthConfig, AuthNeedsAKeyFileAndALongerWindowThanZero) {
  const ConfigResult no_key = load("{window: 1s}");
  ASSERT_EQ(no_key.errors.size(), 1u);
  EXPECT_EQ(no_key.errors.front().path, "segments[1].auth.key_file");
  key_file("lan.key", kKey32, 0600);
  const ConfigResult zero = load("{key_file: lan.key, window: 0ms}");
  ASSERT_EQ(zero.errors.size(), 1u);
  EXPECT_EQ(zero.errors.front().path, "segments[1].auth.window");
  const ConfigResult unknown = load("{key_file: lan.key, keyfile: lan.key}");
  ASSERT_EQ(unknown.errors.size(), 1u);
  EXPECT_NE(unknown.errors.front().message.find("unknown key 'keyfile'"), std::string::npos);
}

TEST_F(LcmAuthConfig, AdmissionCountsTheTrailerOnTheAuthenticatedHop) {
  key_file("lan.key", kKey32, 0600);
  const ConfigResult result = load("{key_file: lan.key}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const Evaluation e = evaluate(result.config.gateway, result.config.segments, result.config.channels, {});
  const ChannelReport& r = e.channels.front();
  EXPECT_EQ(r.verdict, Verdict::bound);
  const HopReport& lan = r.hops.front().segment == "lan" ? r.hops.front() : r.hops.back();
  const HopReport& dds = r.hops.front().segment == "lan" ? r.hops.back() : r.hops.front();
  ASSERT_TRUE(lan.security);
  EXPECT_EQ(lan.security->bytes, 40u);
  EXPECT_EQ(lan.security->scheme, "HMAC-SHA256 trailer");
  EXPECT_FALSE(dds.security);
  const auto fit =
      std::find_if(lan.checks.begin(), lan.checks.end(), [](const Check& c) { return c.check == "frame_fit"; });
  ASSERT_NE(fit, lan.checks.end());
  EXPECT_EQ(fit->value, 16.0 + 40.0);
  // 16 B payload + 96 B of headers + 40 B of trailer every 10 ms.
  const auto load_of = [&](const std::string& name) {
    for (std::size_t i = 0; i < result.config.segments.size(); ++i)
      if (result.config.segments[i].name == name) return e.segments[i].utilization;
    return -1.0;
  };
  const double bandwidth = static_cast<double>(result.config.find_segment("lan")->bandwidth.bits_per_second);
  EXPECT_NEAR(load_of("lan"), (16 + 96 + 40) * 8 / 0.010 / bandwidth, 1e-12);
}

TEST_F(LcmAuthConfig, TheCalibratedCostIsPartOfTheHopsLatencyAndShown) {
  key_file("lan.key", kKey32, 0600);
  const ConfigResult result = load("{key_file: lan.key, cost: 40ms}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  EXPECT_EQ(result.config.find_segment("lan")->lcm.auth->cost, std::chrono::milliseconds(40));
  const Evaluation e = evaluate(result.config.gateway, result.config.segments, result.config.channels, {});
  const ChannelReport& r = e.channels.front();
  const HopReport& lan = r.hops.front().segment == "lan" ? r.hops.front() : r.hops.back();
  ASSERT_TRUE(lan.security && lan.security->time);
  EXPECT_EQ(*lan.security->time, std::chrono::milliseconds(40));
  // The segment's latency_bound (10 ms by default) and the 40 ms: 50 ms, and the channel's 50 ms
  // reaction time is missed once the gateway's residence is added; SRT degrades.
  EXPECT_EQ(lan.latency, std::chrono::milliseconds(50));
  EXPECT_EQ(r.verdict, Verdict::degraded);
  const std::string text = render_channel_text(r);
  EXPECT_NE(text.find("signed HMAC-SHA256 trailer +40 B 40 ms"), std::string::npos) << text;
}

TEST_F(LcmAuthConfig, ARawChannelOnAnAuthenticatedSegmentIsRejectedWithTheReason) {
  key_file("lan.key", kKey32, 0600);
  const ConfigResult result = load("{key_file: lan.key}", "raw");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const Evaluation e = evaluate(result.config.gateway, result.config.segments, result.config.channels, {});
  const ChannelReport& r = e.channels.front();
  EXPECT_EQ(r.verdict, Verdict::rejected);
  ASSERT_EQ(r.reasons.size(), 1u);
  EXPECT_EQ(r.reasons.front(),
            "raw LCM messages on lan cannot carry the authentication trailer the segment requires (auth): use "
            "encoding: envelope");
}

}  // namespace
}  // namespace cosmic

// A channel's `secoc: {SEGMENT: {key_file, mac_bits, freshness_bits, data_id, cost}}` (issue 36,
// item 4): the key file as the loader reads it (an AES-128 key only its owner may read), every
// refusal located at its key, and what admission makes of a SecOC hop (the longer frame in the
// frame fit, the load and the response time; never fragmented; FAMOUSO's layout refused; the
// calibrated cost in the hop's latency).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cosmic/admission.hpp"
#include "cosmic/can_timing.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/report.hpp"

namespace cosmic {
namespace {

const std::string kKey16 = "2b7e151628aed2a6abf7158809cf4f3c\n";  // RFC 4493's key

class SecocConfig : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / ("secoc_config_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    key_file("body.key", kKey16, 0600);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  void key_file(const std::string& name, const std::string& text, unsigned mode) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    ::chmod(path.c_str(), mode);
  }

  // A CAN bus (classic, 500 kbit/s), a FAMOUSO bus and a DDS segment; channel `brake` from DDS to
  // `bus` with `secoc` as given, its class and payload as given.
  ConfigResult load(const std::string& secoc, const std::string& cls = "hrt", const std::string& payload = "4B",
                    const std::string& to = "bus") {
    const std::string text =
        "segments:\n"
        "  - {name: bus, type: can, interface: vcan0, bitrate: 500kbit/s}\n"
        "  - {name: old, type: can, interface: vcan1, bitrate: 500kbit/s, profile: famouso}\n"
        "  - {name: dds, type: dds, domain: 3, realtime: true}\n"
        "channels:\n"
        "  - {name: brake, subject: 0x10, class: " +
        cls + ", period: 10ms, reaction_time: 20ms, payload: " + payload + ",\n     publishers: [dds], subscribers: [" +
        to + "],\n     secoc: " + secoc + "}\n";
    return parse_config(text, (dir_ / "gateway.yaml").string());
  }

  static const HopReport& hop(const ChannelReport& r, const std::string& segment) {
    for (const HopReport& h : r.hops)
      if (h.segment == segment) return h;
    throw std::runtime_error("no hop on " + segment);
  }

  static const Check* check(const HopReport& h, const std::string& name) {
    for (const Check& c : h.checks)
      if (c.check == name) return &c;
    return nullptr;
  }

  static ChannelReport evaluate_first(const ConfigResult& result) {
    return evaluate(result.config.gateway, result.config.segments, result.config.channels, {}).channels.front();
  }

  std::filesystem::path dir_;
};

TEST_F(SecocConfig, AnEntryIsReadWithAutosarsProfileOneByDefault) {
  const ConfigResult result = load("{bus: {key_file: body.key}}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const SecocSpec* spec = result.config.channels.front().secoc_on("bus");
  ASSERT_NE(spec, nullptr);
  EXPECT_EQ(spec->key_file, (dir_ / "body.key").string());
  ASSERT_EQ(spec->key.size(), 16u);
  EXPECT_EQ(spec->key.bytes()[0], 0x2b);
  EXPECT_EQ(spec->mac_bits, 24u);
  EXPECT_EQ(spec->freshness_bits, 8u);
  EXPECT_FALSE(spec->data_id);
  EXPECT_EQ(spec->overhead_bytes(), 4u);
  EXPECT_EQ(result.config.channels.front().secoc_on("dds"), nullptr);

  const ConfigResult given =
      load("{bus: {key_file: body.key, mac_bits: 32, freshness_bits: 16, data_id: 0x1234, cost: 50us}}");
  ASSERT_TRUE(given.errors.empty()) << given.errors.front().to_string();
  const SecocSpec& g = *given.config.channels.front().secoc_on("bus");
  EXPECT_EQ(g.mac_bits, 32u);
  EXPECT_EQ(g.freshness_bits, 16u);
  EXPECT_EQ(g.data_id, 0x1234u);
  EXPECT_EQ(g.cost, std::chrono::microseconds(50));
}

TEST_F(SecocConfig, EveryRefusalIsAtItsKey) {
  key_file("long.key", "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f\n", 0600);
  key_file("open.key", kKey16, 0644);
  const struct {
    std::string secoc;
    std::string path;
    std::string message;
  } cases[] = {
      {"{bus: {key_file: body.key, mac_bits: 12}}", "channels[0].secoc.bus.mac_bits", "not a whole number of bytes"},
      {"{bus: {key_file: body.key, mac_bits: 136}}", "channels[0].secoc.bus.mac_bits", ""},
      {"{bus: {key_file: body.key, freshness_bits: 0}}", "channels[0].secoc.bus.freshness_bits", ""},
      {"{bus: {key_file: body.key, data_id: 0x100000000}}", "channels[0].secoc.bus.data_id", ""},
      {"{bus: {key_file: body.key, cost: fast}}", "channels[0].secoc.bus.cost", ""},
      {"{bus: {key_file: long.key}}", "channels[0].secoc.bus.key_file", "holds no key"},
      {"{bus: {key_file: open.key}}", "channels[0].secoc.bus.key_file", "group or others may read or write it"},
      {"{bus: {key_file: missing.key}}", "channels[0].secoc.bus.key_file", "cannot use key file"},
      {"{bus: {mac_bits: 24}}", "channels[0].secoc.bus.key_file", "missing required key 'key_file'"},
      {"{bus: {key_file: body.key, mac: 24}}", "channels[0].secoc.bus.mac", "unknown key 'mac'"},
      {"{dds: {key_file: body.key}}", "channels[0].secoc.dds", "not a CAN segment"},
      {"{nowhere: {key_file: body.key}}", "channels[0].secoc.nowhere", "unknown segment 'nowhere'"},
      {"{old: {key_file: body.key}}", "channels[0].secoc.old", "neither a publisher nor a subscriber"},
      {"[bus]", "channels[0].secoc", "expected a map"},
  };
  for (const auto& c : cases) {
    const ConfigResult result = load(c.secoc);
    ASSERT_EQ(result.errors.size(), 1u) << c.secoc;
    EXPECT_EQ(result.errors.front().path, c.path) << c.secoc << ": " << result.errors.front().to_string();
    EXPECT_NE(result.errors.front().message.find(c.message), std::string::npos)
        << c.secoc << ": " << result.errors.front().to_string();
    EXPECT_EQ(result.errors.front().message.find("2b7e1516"), std::string::npos) << "a key is never quoted";
    EXPECT_GT(result.errors.front().line, 0);
  }
}

TEST_F(SecocConfig, AdmissionCountsTheLongerFrameInItsFitLoadAndResponseTime) {
  const ConfigResult plain_config = load("{}");
  ASSERT_TRUE(plain_config.errors.empty()) << plain_config.errors.front().to_string();
  const ConfigResult result = load("{bus: {key_file: body.key}}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const ChannelReport plain = evaluate_first(plain_config);
  const ChannelReport secured = evaluate_first(result);
  ASSERT_EQ(secured.verdict, Verdict::bound) << render_channel_text(secured);
  const HopReport& bus = hop(secured, "bus");
  ASSERT_TRUE(bus.security);
  EXPECT_EQ(bus.security->bytes, 4u);
  EXPECT_EQ(bus.security->scheme, "SecOC AES-128-CMAC 24-bit MAC, 8-bit freshness");
  EXPECT_FALSE(bus.security->time);
  EXPECT_FALSE(hop(secured, "dds").security);
  ASSERT_NE(check(bus, "frame_fit"), nullptr);
  EXPECT_EQ(check(bus, "frame_fit")->value, 8.0);
  ASSERT_TRUE(bus.can);
  EXPECT_EQ(bus.can->frame_bytes, 8u);
  EXPECT_EQ(hop(plain, "bus").can->frame_bytes, 4u);
  // An 8-byte extended frame takes longer than a 4-byte one: the transmission time, the load and
  // the response time grow with it.
  const SegmentSpec& can = *result.config.find_segment("bus");
  EXPECT_EQ(bus.can->transmission, frame_time(can.can, 8, CanIdFormat::extended29));
  EXPECT_GT(bus.can->transmission, hop(plain, "bus").can->transmission);
  EXPECT_GT(*bus.latency, *hop(plain, "bus").latency);
  EXPECT_GT(check(bus, "utilization")->value, check(hop(plain, "bus"), "utilization")->value);
  const std::string text = render_channel_text(secured);
  EXPECT_NE(text.find("SecOC AES-128-CMAC 24-bit MAC, 8-bit freshness +4 B"), std::string::npos) << text;
}

TEST_F(SecocConfig, AFrameThatNoLongerFitsIsRejectedAndNeverFragmented) {
  const ConfigResult hrt = load("{bus: {key_file: body.key}}", "hrt", "6B");
  ASSERT_TRUE(hrt.errors.empty()) << hrt.errors.front().to_string();
  const ChannelReport r = evaluate_first(hrt);
  EXPECT_EQ(r.verdict, Verdict::rejected);
  const std::string reasons = render_channel_text(r);
  EXPECT_NE(reasons.find("payload 6 B + SecOC 4 B > frame 8 B on bus"), std::string::npos) << reasons;
  // NRT would fragment 10 bytes; with SecOC it may not.
  const ConfigResult nrt = load("{bus: {key_file: body.key}}", "nrt", "10B");
  ASSERT_TRUE(nrt.errors.empty()) << nrt.errors.front().to_string();
  const ChannelReport n = evaluate_first(nrt);
  EXPECT_EQ(n.verdict, Verdict::rejected);
  EXPECT_NE(render_channel_text(n).find("payload 10 B + SecOC 4 B > frame 8 B on bus"), std::string::npos)
      << render_channel_text(n);
}

TEST_F(SecocConfig, FamousosLayoutCannotCarryIt) {
  const ConfigResult result = load("{old: {key_file: body.key}}", "srt", "4B", "old");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const ChannelReport r = evaluate_first(result);
  EXPECT_EQ(r.verdict, Verdict::rejected);
  EXPECT_NE(render_channel_text(r).find("SecOC on old needs this project's frame layout"), std::string::npos)
      << render_channel_text(r);
}

TEST_F(SecocConfig, TheCalibratedCostIsPartOfTheHopsLatency) {
  const ConfigResult plain_config = load("{bus: {key_file: body.key}}");
  const ConfigResult result = load("{bus: {key_file: body.key, cost: 3ms}}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const HopReport without = hop(evaluate_first(plain_config), "bus");
  const ChannelReport r = evaluate_first(result);
  const HopReport& bus = hop(r, "bus");
  ASSERT_TRUE(bus.security && bus.security->time);
  EXPECT_EQ(*bus.latency - *without.latency, std::chrono::milliseconds(3));
  EXPECT_NE(render_channel_text(r).find("+4 B 3 ms"), std::string::npos) << render_channel_text(r);
}

// CAN to CAN with SecOC on both hops: verifying after the publisher hop and protecting before the
// subscriber hop each count once, end to end, and protecting delays the frame's release (its jitter).
TEST_F(SecocConfig, BothCostsCountOnceEndToEnd) {
  const auto both = [&](const std::string& in, const std::string& out) {
    const std::string text =
        "segments:\n"
        "  - {name: bus, type: can, interface: vcan0, bitrate: 500kbit/s}\n"
        "  - {name: other, type: can, interface: vcan1, bitrate: 500kbit/s}\n"
        "channels:\n"
        "  - {name: brake, subject: 0x10, class: srt, period: 10ms, reaction_time: 40ms, payload: 4B,\n"
        "     publishers: [bus], subscribers: [other],\n"
        "     secoc: {bus: {key_file: body.key" +
        in + "}, other: {key_file: body.key" + out + "}}}\n";
    const ConfigResult result = parse_config(text, (dir_ / "gateway.yaml").string());
    EXPECT_TRUE(result.errors.empty()) << result.errors.front().to_string();
    return evaluate_first(result);
  };
  const ChannelReport plain = both("", "");
  const ChannelReport costed = both(", cost: 1ms", ", cost: 2ms");
  ASSERT_TRUE(plain.end_to_end.latency && costed.end_to_end.latency);
  EXPECT_EQ(*costed.end_to_end.latency - *plain.end_to_end.latency, std::chrono::milliseconds(3));
  EXPECT_EQ(hop(costed, "other").can->jitter - hop(plain, "other").can->jitter, std::chrono::milliseconds(1 + 2))
      << "the subscriber frame is released after the publisher hop's check and its own protection";
}

TEST_F(SecocConfig, ARuntimeBindingKeepsItsSecocEntryButNeverTheKey) {
  const ConfigResult result = load("{bus: {key_file: body.key, data_id: 7, cost: 1ms}}");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const std::string yaml = channel_to_yaml(result.config.channels.front());
  EXPECT_NE(yaml.find("secoc: {bus: {key_file: " + (dir_ / "body.key").string() +
                      ", mac_bits: 24, freshness_bits: 8, data_id: 7, cost: 1000000ns}}"),
            std::string::npos)
      << yaml;
  EXPECT_EQ(yaml.find("2b7e"), std::string::npos);
}

}  // namespace
}  // namespace cosmic

// Reports: the JSON contract of `cosmicctl check --json` (issue 2, item 5) and the text table.
#include "cosmic/report.hpp"

#include <gtest/gtest.h>

#include "cosmic/knowledge_base.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using namespace cosmic::test;
using nlohmann::json;

// A 125 kbit/s bus with an HRT channel that fits, an SRT channel that misses its reaction time
// and a rejected one; plus an overloaded SRT pair (unbounded).
Config sample_config() {
  Config config;
  config.gateway = gateway(100us);
  config.segments = {can_segment("can", 125'000), dds_segment("lan", 100us), lcm_segment("viz")};
  // HRT: 8 B, 1.28 ms; R = 1.28 + blocking 1.28 = 2.56 ms <= 5 ms.
  config.channels.push_back(channel("brake", 1, ChannelClass::hrt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(5ms)));
  // SRT, 2 ms reaction: R = 1.28 (brake) + 1.28 = 2.56 ms > 2 ms: degraded.
  config.channels.push_back(channel("steer", 2, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(10ms), Nanos(2ms)));
  // 9 B on classic CAN: rejected.
  config.channels.push_back(channel("big", 3, ChannelClass::srt, {"can"}, {"lan"}, 9));
  // NRT to LCM, no reaction time.
  config.channels.push_back(channel("log", 4, ChannelClass::nrt, {"lan"}, {"viz"}, 100, Nanos(100ms)));
  return config;
}

const json& channel_named(const json& report, const std::string& name) {
  for (const auto& c : report.at("channels")) {
    if (c.at("name") == name) return c;
  }
  throw std::runtime_error("no channel " + name);
}

TEST(JsonReport, ShapeOfTheContract) {
  const json j = to_json(admit_all(sample_config()));
  ASSERT_TRUE(j.is_object());
  ASSERT_TRUE(j.at("segments").is_array());
  ASSERT_EQ(j.at("segments").size(), 3u);
  for (const auto& s : j.at("segments")) {
    EXPECT_TRUE(s.at("name").is_string());
    EXPECT_TRUE(s.at("type").is_string());
    EXPECT_TRUE(s.at("utilization").is_number());
    EXPECT_TRUE(s.at("max_utilization").is_number());
  }
  EXPECT_EQ(j["segments"][0]["name"], "can");
  EXPECT_EQ(j["segments"][0]["type"], "can");
  EXPECT_EQ(j["segments"][1]["type"], "dds");
  EXPECT_EQ(j["segments"][2]["type"], "lcm");
  EXPECT_DOUBLE_EQ(j["segments"][0]["max_utilization"].get<double>(), 0.7);
  // brake + steer: 2 * 1.28 / 10 = 0.256 (big is rejected, reserves nothing).
  EXPECT_NEAR(j["segments"][0]["utilization"].get<double>(), 0.256, 1e-12);

  ASSERT_TRUE(j.at("channels").is_array());
  ASSERT_EQ(j.at("channels").size(), 4u);
  for (const auto& c : j.at("channels")) {
    EXPECT_TRUE(c.at("name").is_string());
    EXPECT_TRUE(c.at("class") == "hrt" || c.at("class") == "srt" || c.at("class") == "nrt");
    EXPECT_TRUE(c.at("verdict") == "bound" || c.at("verdict") == "degraded" || c.at("verdict") == "rejected");
    EXPECT_TRUE(c.at("reasons").is_array());
    ASSERT_TRUE(c.at("hops").is_array());
    for (const auto& h : c.at("hops")) {
      EXPECT_TRUE(h.at("segment").is_string());
      EXPECT_TRUE(h.at("role") == "publisher" || h.at("role") == "subscriber");
      ASSERT_TRUE(h.at("checks").is_array());
      for (const auto& check : h.at("checks")) {
        EXPECT_TRUE(check.at("check").is_string());
        EXPECT_TRUE(check.at("value").is_number() || check.at("value").is_null());
        EXPECT_TRUE(check.at("limit").is_number());
        EXPECT_TRUE(check.at("unit").is_string());
        EXPECT_TRUE(check.at("ok").is_boolean());
      }
      // "can" only on CAN hops.
      EXPECT_EQ(h.contains("can"), h.at("segment") == "can") << h.dump();
      if (h.contains("can")) {
        const json& can = h.at("can");
        for (const char* key : {"priority", "can_id", "etag", "frame_bytes", "transmission_time_s"}) {
          EXPECT_TRUE(can.at(key).is_number()) << key;
        }
        EXPECT_TRUE(can.at("response_time_s").is_number() || can.at("response_time_s").is_null());
      }
    }
    const json& e2e = c.at("end_to_end");
    EXPECT_TRUE(e2e.at("latency_s").is_number() || e2e.at("latency_s").is_null());
    EXPECT_TRUE(e2e.at("reaction_time_s").is_number() || e2e.at("reaction_time_s").is_null());
    EXPECT_TRUE(e2e.at("ok").is_boolean());
  }
  // Bound and degraded first in bind order, then rejected.
  EXPECT_EQ(j["channels"][0]["name"], "brake");
  EXPECT_EQ(j["channels"][1]["name"], "steer");
  EXPECT_EQ(j["channels"][2]["name"], "log");
  EXPECT_EQ(j["channels"][3]["name"], "big");
}

TEST(JsonReport, Values) {
  const json j = to_json(admit_all(sample_config()));
  const json& brake = channel_named(j, "brake");
  EXPECT_EQ(brake["verdict"], "bound");
  EXPECT_EQ(brake["class"], "hrt");
  EXPECT_TRUE(brake["reasons"].empty());
  const json& hop = brake["hops"][0];
  EXPECT_EQ(hop["segment"], "can");
  EXPECT_EQ(hop["role"], "publisher");
  EXPECT_EQ(hop["can"]["priority"], 0);
  EXPECT_EQ(hop["can"]["etag"], 16383);
  EXPECT_EQ(hop["can"]["can_id"], (0u << 21) | (1u << 14) | 16383u);  // 29-bit identifier
  EXPECT_EQ(hop["can"]["layout"], "cosmic");
  EXPECT_EQ(hop["can"]["tx_node"], 1);
  EXPECT_FALSE(hop["can"].contains("fragment"));  // a FAMOUSO field
  EXPECT_EQ(hop["can"]["frame_bytes"], 8);
  EXPECT_DOUBLE_EQ(hop["can"]["transmission_time_s"].get<double>(), 0.00128);
  EXPECT_DOUBLE_EQ(hop["can"]["response_time_s"].get<double>(), 0.00256);
  // e2e = 2.56 + 0.1 + 0.1 = 2.76 ms.
  EXPECT_NEAR(brake["end_to_end"]["latency_s"].get<double>(), 0.00276, 1e-12);
  EXPECT_DOUBLE_EQ(brake["end_to_end"]["reaction_time_s"].get<double>(), 0.005);
  EXPECT_EQ(brake["end_to_end"]["ok"], true);

  const json& steer = channel_named(j, "steer");
  EXPECT_EQ(steer["verdict"], "degraded");
  EXPECT_EQ(steer["hops"][0]["can"]["priority"], 0x10);
  bool found = false;
  for (const auto& check : steer["hops"][0]["checks"]) {
    if (check["check"] != "response_time") continue;
    found = true;
    EXPECT_DOUBLE_EQ(check["value"].get<double>(), 0.00256);
    EXPECT_DOUBLE_EQ(check["limit"].get<double>(), 0.002);
    EXPECT_EQ(check["unit"], "s");
    EXPECT_EQ(check["ok"], false);
  }
  EXPECT_TRUE(found);
  EXPECT_EQ(steer["end_to_end"]["ok"], false);

  const json& log = channel_named(j, "log");
  EXPECT_TRUE(log["end_to_end"]["reaction_time_s"].is_null());  // NRT: no bound asked
  EXPECT_FALSE(log["hops"][0].contains("can"));

  const json& big = channel_named(j, "big");
  EXPECT_EQ(big["verdict"], "rejected");
  ASSERT_FALSE(big["reasons"].empty());
  EXPECT_EQ(big["reasons"][0], "payload 9 B > frame 8 B on can");
}

TEST(JsonReport, UnboundedIsNull) {
  // Two 8 B frames every 2 ms on 125 kbit/s: 128 %, the lower one has no bound.
  const auto e = evaluate(
      gateway(), std::vector<SegmentSpec>{can_segment("can", 125'000), dds_segment("lan")},
      std::vector<ChannelSpec>{channel("a", 1, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(2ms), Nanos(10ms)),
                               channel("b", 2, ChannelClass::srt, {"can"}, {"lan"}, 8, Nanos(2ms), Nanos(10ms))},
      {});
  const json b = to_json(e.channels[1]);
  EXPECT_TRUE(b["hops"][0]["can"]["response_time_s"].is_null());
  EXPECT_TRUE(b["end_to_end"]["latency_s"].is_null());
  EXPECT_EQ(b["end_to_end"]["ok"], false);
  for (const auto& check : b["hops"][0]["checks"]) {
    if (check["check"] == "response_time") {
      EXPECT_TRUE(check["value"].is_null());
    }
  }
  EXPECT_NO_THROW((void)b.dump());  // no inf or nan reaches the JSON text
}

TEST(JsonReport, ConfigErrors) {
  const ConfigResult r = parse_config("segments: []\nchannels: []\nextra: 1\n", "x.yaml");
  const json j = to_json(r.errors);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["file"], "x.yaml");
  EXPECT_EQ(j[0]["line"], 3);
  EXPECT_EQ(j[0]["column"], 1);
  EXPECT_EQ(j[0]["path"], "extra");
  EXPECT_EQ(j[0]["message"], "unknown key 'extra'");
  EXPECT_EQ(j[0]["text"], r.errors[0].to_string());
}

TEST(TextReport, TableWithReasons) {
  const std::string text = render_text(admit_all(sample_config()));
  EXPECT_NE(text.find("SEGMENT"), std::string::npos);
  EXPECT_NE(text.find("can             can   25.6%        70.0%"), std::string::npos) << text;
  EXPECT_NE(text.find("brake"), std::string::npos);
  EXPECT_NE(text.find("R = 2.56 ms > reaction_time 2 ms on can"), std::string::npos) << text;
  EXPECT_NE(text.find("payload 9 B > frame 8 B on can"), std::string::npos) << text;
  EXPECT_NE(text.find("<= 5 ms required"), std::string::npos) << text;
  EXPECT_NE(text.find("2 bound, 1 degraded, 1 rejected"), std::string::npos) << text;
}

TEST(TextReport, ChannelDetail) {
  const AdmissionReport report = admit_all(sample_config());
  const std::string text = render_channel_text(*report.find("steer"));
  EXPECT_NE(text.find("steer (srt): degraded"), std::string::npos) << text;
  // priority 0x10, node 1, etag 16382: 0x10 << 21 | 1 << 14 | 16382 = 0x02007FFE.
  EXPECT_NE(text.find("id 0x02007FFE (priority 0x10, TxNode 1, etag 16382)"), std::string::npos) << text;
  EXPECT_NE(text.find("FAIL response_time"), std::string::npos) << text;
  EXPECT_NE(text.find("2.56 ms <= 2 ms"), std::string::npos) << text;
  EXPECT_NE(text.find("ok   frame_fit"), std::string::npos) << text;
  EXPECT_NE(text.find("end-to-end 2.76 ms, reaction_time 2 ms  FAIL"), std::string::npos) << text;
}

// A FAMOUSO segment's hops in FAMOUSO's layout (docs/can-wire-format.md section 8): JSON and text.
TEST(JsonReport, FamousoHopsInFamousosLayout) {
  Config config;
  config.gateway = gateway(100us, 9);
  config.segments = {can_segment("bus"), dds_segment("lan", 100us)};
  config.segments[0].can.profile = CanProfile::famouso;
  ChannelSpec command = channel("command", 2, ChannelClass::srt, {"lan"}, {"bus"}, 6, Nanos(10ms), Nanos(50ms));
  command.etag = 300;
  ChannelSpec bulk = channel("bulk", 3, ChannelClass::nrt, {"lan"}, {"bus"}, 100, Nanos(100ms));
  bulk.etag = 202;
  config.channels = {command, bulk};
  const AdmissionReport report = admit_all(config);
  const json j = to_json(report);
  const json& cmd = channel_named(j, "command")["hops"][1]["can"];
  EXPECT_EQ(cmd["layout"], "famouso");
  EXPECT_EQ(cmd["priority"], 0x10);  // 7 bits
  EXPECT_EQ(cmd["fragment"], false);
  EXPECT_EQ(cmd["tx_node"], 9);
  EXPECT_EQ(cmd["etag"], 300);
  EXPECT_EQ(cmd["can_id"], 0x0402412Cu);  // (0x10 << 22) | (9 << 14) | 300
  const json& frag = channel_named(j, "bulk")["hops"][1]["can"];
  EXPECT_EQ(frag["priority"], 0x78);
  EXPECT_EQ(frag["fragment"], true);
  EXPECT_EQ(frag["can_id"], (0x78u << 22) | (1u << 21) | (9u << 14) | 202u);
  const std::string text = render_channel_text(*report.find("command"));
  EXPECT_NE(text.find("id 0x0402412C (FAMOUSO layout: priority 0x10, fragment 0, TxNode 9, etag 300)"),
            std::string::npos)
      << text;
  EXPECT_EQ(can_identifier_text(0x1E2140C9u, CanProfile::famouso),
            "0x1E2140C9 (FAMOUSO layout: priority 0x78, fragment 1, TxNode 5, etag 201)");
  EXPECT_EQ(can_identifier_text(0x1E2140C9u, CanProfile::cosmic), "0x1E2140C9 (priority 0xF1, TxNode 5, etag 201)");
}

}  // namespace
}  // namespace cosmic

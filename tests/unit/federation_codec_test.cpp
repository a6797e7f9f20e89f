// The federation announcement codec (cosmic/federation.hpp): a round trip keeps every field, and a
// hostile or broken announcement is refused with the reason, never applied and never a crash.
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>

#include "cosmic/federation.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using Json = nlohmann::json;

Announcement sample_announcement() {
  Announcement a;
  a.gateway = 0x1234abcd5678ef01;
  a.name = "gw2";
  a.revision = 7;
  a.residence = Nanos(500us);
  AnnouncedSegment lan{"lan", SegmentType::dds, "dds:domain=0", 0.7, 0.125, 12'500'000, {}};
  AnnouncedSegment body{"body", SegmentType::can, "can:body", 0.6, 0.2, 0, {}};
  body.frames.push_back(AnnouncedFrame{"steer", 0x0C0FFFFF, true, 8, Nanos(10ms), Nanos(250us), Nanos(3ms)});
  body.frames.push_back(AnnouncedFrame{"ecu", 0x123, false, 4, Nanos(20ms), Nanos(0), std::nullopt});
  a.segments = {lan, body};
  AnnouncedChannel steer;
  steer.name = "steer";
  steer.subject = 0x100000042;
  steer.cls = ChannelClass::hrt;
  steer.hops = {AnnouncedHop{"lan", HopRole::publisher, Nanos(1ms)},
                AnnouncedHop{"body", HopRole::subscriber, Nanos(1500us)}};
  steer.end_to_end = Nanos(5ms);
  steer.period = Nanos(10ms);
  steer.reaction_time = Nanos(20ms);
  steer.temp_validity = Nanos(50ms);
  steer.payload = 8;
  steer.upstream = {PathHop{"gw1", "front-can", HopRole::publisher, Nanos(1ms), 0x77}};
  steer.upstream_age = Nanos(2ms);
  steer.violated = true;
  AnnouncedChannel log;
  log.name = "log";
  log.subject = 7;
  log.verdict = Verdict::degraded;
  log.hops = {AnnouncedHop{"lan", HopRole::subscriber, std::nullopt}};
  log.end_to_end = std::nullopt;
  log.upstream_age = std::nullopt;
  a.channels = {steer, log};
  a.claim = a.segments;
  a.claim->front().load = 0.3;
  return a;
}

TEST(FederationCodec, RoundTripKeepsEveryField) {
  const Announcement a = sample_announcement();
  const DecodedAnnouncement decoded = decode_announcement(encode(a));
  ASSERT_TRUE(decoded.announcement) << decoded.error;
  EXPECT_EQ(*decoded.announcement, a);
}

TEST(FederationCodec, GatewayIdsAreSixteenHexDigits) {
  EXPECT_EQ(gateway_id_text(0xdeadbeef), "00000000deadbeef");
  EXPECT_EQ(gateway_id_text(UINT64_MAX), "ffffffffffffffff");
}

struct Hostile {
  const char* what;
  std::function<void(Json&)> change;
  const char* error;  // a fragment of the refusal
};

TEST(FederationCodec, RefusesMalformedAndOutOfRangeAnnouncements) {
  const std::vector<Hostile> cases = {
      {"another format", [](Json& j) { j["format"] = "cosmic-federation/2"; }, "format"},
      {"id zero", [](Json& j) { j["gateway"] = "0000000000000000"; }, "gateway is 0"},
      {"id upper case", [](Json& j) { j["gateway"] = "1234ABCD5678EF01"; }, "lower-case"},
      {"id short", [](Json& j) { j["gateway"] = "1234"; }, "16 hexadecimal"},
      {"id a number", [](Json& j) { j["gateway"] = 5; }, "not a string"},
      {"negative revision", [](Json& j) { j["revision"] = -1; }, "revision"},
      {"fractional revision", [](Json& j) { j["revision"] = 1.5; }, "revision"},
      {"negative load", [](Json& j) { j["segments"][0]["load"] = -0.1; }, "load is outside 0..1"},
      {"load above one", [](Json& j) { j["segments"][0]["load"] = 1.5; }, "load is outside 0..1"},
      {"unknown type", [](Json& j) { j["segments"][0]["type"] = "tsn"; }, "not a known value"},
      {"frames on DDS", [](Json& j) { j["segments"][0]["frames"] = j["segments"][1]["frames"]; },
       "frames is not empty on a dds"},
      {"identifier over 29 bits", [](Json& j) { j["segments"][1]["frames"][0]["can_id"] = 0x20000000; }, "can_id"},
      {"standard identifier over 11 bits", [](Json& j) { j["segments"][1]["frames"][1]["can_id"] = 0x800; }, "can_id"},
      {"zero period", [](Json& j) { j["segments"][1]["frames"][0]["period_ns"] = 0; }, "below 1 us"},
      {"negative jitter", [](Json& j) { j["segments"][1]["frames"][0]["jitter_ns"] = -5; }, "jitter_ns"},
      {"jitter of an hour", [](Json& j) { j["segments"][1]["frames"][0]["jitter_ns"] = 3'600'000'000'000LL; },
       "above 1 s"},
      {"bandwidth beyond a terabit", [](Json& j) { j["segments"][0]["reserved_bps"] = 2e12; },
       "reserved_bps is outside"},
      {"negative bandwidth", [](Json& j) { j["segments"][0]["reserved_bps"] = -1; }, "reserved_bps is outside"},
      {"frame of 65 bytes", [](Json& j) { j["segments"][1]["frames"][0]["length"] = 65; }, "length"},
      {"negative latency", [](Json& j) { j["channels"][0]["hops"][0]["latency_ns"] = -1; }, "latency_ns"},
      {"latency of years", [](Json& j) { j["channels"][0]["end_to_end_ns"] = 86'400'000'000'001LL; },
       "is above 86400000000000"},
      {"fractional latency", [](Json& j) { j["channels"][0]["end_to_end_ns"] = 1e18; }, "not a whole number"},
      {"unknown verdict", [](Json& j) { j["channels"][0]["verdict"] = "rejected"; }, "not a known value"},
      {"control character", [](Json& j) { j["name"] = "gw\x1b[2J"; }, "control character"},
      {"long name", [](Json& j) { j["name"] = std::string(200, 'x'); }, "longer than"},
      {"missing field", [](Json& j) { j.erase("segments"); }, "segments is missing"},
      {"segment not an object", [](Json& j) { j["segments"][0] = 3; }, "is not an object"},
      {"too many segments",
       [](Json& j) {
         j["segments"] = Json::array();
         for (int i = 0; i < 65; ++i) j["segments"].push_back(j["segments"].size());
       },
       "more than 64"},
      {"claim not a list", [](Json& j) { j["claim"] = 3; }, "claim is not a list"},
      {"claim with a bad load", [](Json& j) { j["claim"][0]["load"] = 2; }, "claim[0].load is outside"},
      {"negative residence", [](Json& j) { j["residence_ns"] = -1; }, "residence_ns"},
      {"upstream hop with id 0", [](Json& j) { j["channels"][0]["upstream"][0]["gateway_id"] = "0000000000000000"; },
       "gateway_id is 0"},
      {"upstream hop without gateway", [](Json& j) { j["channels"][0]["upstream"][0].erase("gateway"); },
       "gateway is missing"},
      {"fractional payload", [](Json& j) { j["channels"][0]["payload"] = 1.5; }, "payload"},
      {"too many channels", [](Json& j) { j["channels"] = Json(std::vector<int>(kMaxAnnouncedChannels + 1, 0)); },
       "more than 4096"},
  };
  const Json good = Json::parse(encode(sample_announcement()));
  for (const Hostile& c : cases) {
    Json j = good;
    c.change(j);
    const DecodedAnnouncement decoded = decode_announcement(j.dump());
    EXPECT_FALSE(decoded.announcement) << c.what;
    EXPECT_NE(decoded.error.find(c.error), std::string::npos) << c.what << ": " << decoded.error;
  }
}

TEST(FederationCodec, RefusesTextsThatAreNotAnnouncements) {
  EXPECT_NE(decode_announcement("").error.find("not JSON"), std::string::npos);
  EXPECT_NE(decode_announcement("{\"format\":").error.find("not JSON"), std::string::npos);
  EXPECT_NE(decode_announcement("[1,2]").error.find("not an object"), std::string::npos);
  EXPECT_NE(decode_announcement(std::string(100000, '[')).error.find("nests deeper"), std::string::npos);
  EXPECT_NE(decode_announcement(std::string(kMaxAnnouncementBytes + 1, ' ')).error.find("more than 1 MiB"),
            std::string::npos);
}

}  // namespace
}  // namespace cosmic

// YAML configuration: the bundled robot, documented defaults (lib/core/include/cosmic/model.hpp),
// units and derived values, the fault-hypothesis switch, and bind documents.
#include "cosmic/build_paths.hpp"
#include "cosmic/config_loader.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <tuple>

#include "cosmic/knowledge_base.hpp"
#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using cosmic::test::find_hop;
using cosmic::test::reasons_text;

std::string describe(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += "  " + e.to_string() + "\n";
  return out;
}

Config parse_ok(const std::string& text) {
  ConfigResult result = parse_config(text, "test.yaml");
  EXPECT_TRUE(result.ok()) << describe(result.errors);
  return std::move(result.config);
}

TEST(Config, RobotLoadsAndEveryChannelIsBound) {
  const ConfigResult loaded = load_config_file(std::string(cosmic::build_paths::source_dir) + "/config/robot.yaml");
  ASSERT_TRUE(loaded.ok()) << describe(loaded.errors);
  const Config& config = loaded.config;
  EXPECT_EQ(config.gateway.name, "q-robot");
  EXPECT_EQ(config.gateway.can_node_id, 1);
  EXPECT_EQ(config.gateway.residence_bound, Nanos(500us));
  ASSERT_EQ(config.segments.size(), 3u);
  ASSERT_EQ(config.channels.size(), 8u);
  const SegmentSpec& body = *config.find_segment("body-can");
  EXPECT_EQ(body.type, SegmentType::can);
  EXPECT_EQ(body.can.bitrate, BitRate{500'000});
  EXPECT_DOUBLE_EQ(body.max_utilization, 0.7);
  EXPECT_EQ(body.can.errors.max_per_window, 2u);
  EXPECT_EQ(body.can.errors.window, Nanos(10ms));
  EXPECT_TRUE(config.find_segment("lan")->realtime);
  EXPECT_EQ(config.find_segment("viz")->reliability, Reliability::best_effort);
  const ChannelSpec& distance = *config.find_channel("distance");
  EXPECT_EQ(distance.subject, 0x0000000100000042u);
  EXPECT_EQ(distance.cls, ChannelClass::hrt);
  EXPECT_EQ(distance.period, Nanos(10ms));
  EXPECT_EQ(distance.reaction_time, Nanos(5ms));
  EXPECT_EQ(distance.omission_degree, 1u);
  EXPECT_EQ(distance.temp_validity, Nanos(50ms));
  EXPECT_EQ(distance.payload, 4u);
  EXPECT_EQ(distance.publishers, std::vector<std::string>{"body-can"});
  EXPECT_EQ(config.find_channel("command")->period, Nanos(50ms));  // max_rate: 20Hz

  const AdmissionReport report = admit_all(config);
  ASSERT_EQ(report.channels.size(), config.channels.size());
  for (std::size_t i = 0; i < report.channels.size(); ++i) {
    EXPECT_EQ(report.channels[i].name, config.channels[i].name);  // all bound: declaration order
    EXPECT_EQ(report.channels[i].verdict, Verdict::bound) << report.channels[i].name << "\n"
                                                          << reasons_text(report.channels[i]);
    EXPECT_TRUE(report.channels[i].reasons.empty()) << reasons_text(report.channels[i]);
  }
  EXPECT_FALSE(report.any_rejected());
  // The HRT channels get the HRT band, deadline-monotonic: obstacle (4 ms) before distance (5 ms).
  EXPECT_EQ(find_hop(*report.find("obstacle"), "body-can")->can->priority, 0x00);
  EXPECT_EQ(find_hop(*report.find("distance"), "body-can")->can->priority, 0x01);
  EXPECT_EQ(find_hop(*report.find("speed"), "body-can")->can->priority, 0x10);  // 8 ms, first SRT
  EXPECT_GE(find_hop(*report.find("diagnostics"), "body-can")->can->priority, 0xF0);
  EXPECT_GT(find_hop(*report.find("diagnostics"), "body-can")->can->frames_per_event, 1u);  // 256 B NRT fragments
}

TEST(Config, OverloadedExampleTriggersEveryKindOnce) {
  const ConfigResult loaded =
      load_config_file(std::string(cosmic::build_paths::source_dir) + "/config/overloaded.yaml");
  ASSERT_TRUE(loaded.ok()) << describe(loaded.errors);
  const AdmissionReport report = admit_all(loaded.config);
  EXPECT_TRUE(report.any_rejected());
  // channel -> (verdict, the one reason it is there for); figures in config/overloaded.yaml.
  const std::vector<std::tuple<std::string, Verdict, std::string>> expected{
      {"brake_pressure", Verdict::bound, ""},
      {"wheel_speed", Verdict::bound, ""},
      {"battery", Verdict::bound, ""},
      {"diagnostics", Verdict::bound, ""},
      {"collision_warning", Verdict::rejected,
       "would break hrt channel brake_pressure: end-to-end latency 5.34 ms > reaction_time 5 ms"},
      {"emergency_stop", Verdict::rejected, "R = 2 ms > reaction_time 1.5 ms on body-can"},
      {"camera_status", Verdict::rejected, "payload 12 B > frame 8 B on body-can"},
      {"trailer_axle_load", Verdict::degraded, "utilization 64.0% > max_utilization 50.0% on trailer-can"},
      {"arm_torque", Verdict::rejected, "hrt on office, which declares no real-time guarantee (realtime: false)"},
      {"obstacle_map", Verdict::degraded, "end-to-end latency 5.5 ms > reaction_time 5 ms"},
      {"joint_state", Verdict::degraded, "end-to-end latency 5.5 ms >= temp_validity 5 ms: events would arrive stale"},
      {"speed_plot", Verdict::degraded, "omission_degree 0 < 1 on viz, which does not retransmit"}};
  ASSERT_EQ(report.channels.size(), expected.size());
  for (const auto& [name, verdict, reason] : expected) {
    const ChannelReport* c = report.find(name);
    ASSERT_NE(c, nullptr) << name;
    EXPECT_EQ(c->verdict, verdict) << name << "\n" << reasons_text(*c);
    if (reason.empty()) {
      EXPECT_TRUE(c->reasons.empty()) << name << "\n" << reasons_text(*c);
    } else {
      ASSERT_FALSE(c->reasons.empty()) << name;
      EXPECT_EQ(c->reasons[0], reason) << name;
      // One kind per channel; an R miss also misses the end-to-end budget it is part of.
      EXPECT_EQ(c->reasons.size(), name == "emergency_stop" ? 2u : 1u) << name << "\n" << reasons_text(*c);
    }
  }
}

TEST(Config, DocumentedDefaults) {
  const Config config = parse_ok(R"(
segments:
  - {name: bus, type: can, interface: can0, bitrate: 250kbit/s}
  - {name: lan, type: dds}
  - {name: viz, type: lcm}
channels:
  - {name: c, subject: 1, class: nrt, publishers: [bus], subscribers: [lan, viz]}
)");
  EXPECT_EQ(config.gateway.name, "cosmicd");
  EXPECT_EQ(config.gateway.can_node_id, 1);
  EXPECT_EQ(config.gateway.residence_bound, Nanos(1ms));
  EXPECT_EQ(config.gateway.control_socket, "/run/cosmicd/control.sock");

  const SegmentSpec& bus = config.segments[0];
  EXPECT_EQ(bus.can.interface, "can0");
  EXPECT_FALSE(bus.can.fd);
  EXPECT_EQ(bus.can.bitrate, BitRate{250'000});
  EXPECT_EQ(bus.can.data_bitrate, BitRate{250'000});  // equals bitrate when not FD
  EXPECT_EQ(bus.can.errors.max_per_window, 0u);       // error-free bus unless declared
  EXPECT_DOUBLE_EQ(bus.max_utilization, 0.7);

  const SegmentSpec& lan = config.segments[1];
  EXPECT_EQ(lan.dds.domain, 0u);
  EXPECT_EQ(lan.latency_bound, Nanos(10ms));
  EXPECT_EQ(lan.bandwidth, BitRate{100'000'000});
  EXPECT_EQ(lan.reliability, Reliability::reliable);
  EXPECT_FALSE(lan.realtime);  // real-time capability off by default
  EXPECT_EQ(lan.max_message_size, 65000u);
  EXPECT_TRUE(lan.dds.interfaces.empty());
  EXPECT_TRUE(lan.dds.discovery_server.empty());
  EXPECT_DOUBLE_EQ(lan.max_utilization, 0.7);

  const SegmentSpec& viz = config.segments[2];
  EXPECT_EQ(viz.reliability, Reliability::best_effort);  // LCM has no retransmission
  EXPECT_FALSE(viz.realtime);
  EXPECT_EQ(viz.lcm.url, "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(viz.lcm.own_datagrams, LcmOwnDatagrams::drop);  // the default
  EXPECT_EQ(viz.latency_bound, Nanos(10ms));

  const ChannelSpec& c = config.channels[0];
  EXPECT_EQ(c.payload, 8u);
  EXPECT_EQ(c.omission_degree, 0u);
  EXPECT_FALSE(c.period.has_value());
  EXPECT_FALSE(c.reaction_time.has_value());
  EXPECT_FALSE(c.temp_validity.has_value());
  EXPECT_FALSE(c.etag.has_value());
  EXPECT_EQ(c.lcm_encoding, LcmEncoding::envelope);
  EXPECT_EQ(c.subscribers, (std::vector<std::string>{"lan", "viz"}));
}

TEST(Config, EveryKeyParsed) {
  const Config config = parse_ok(R"(
gateway: {name: gw-2, can_node_id: 0x7F, residence_bound: 250us, control_socket: /tmp/gw.sock}
segments:
  - name: fd
    type: can
    interface: can1
    bitrate: 1Mbit/s
    fd: true
    data_bitrate: 5Mbit/s
    max_utilization: 50%
    errors: {max_per_window: 3, window: 20ms}
  - name: lan
    type: dds
    domain: 7
    latency_bound: 250us
    bandwidth: 1Gbit/s
    reliability: best_effort
    realtime: true
    max_message_size: 1KiB
    interfaces: [eth0, lo]
    discovery_server: 127.0.0.1:11811
  - {name: viz, type: lcm, url: "memq://", latency_bound: 2ms, bandwidth: 10Mbit/s, own_datagrams: cut}
channels:
  - name: c
    subject: 18446744073709551615
    class: srt
    max_rate: 2.5kHz
    reaction_time: 3ms
    omission_degree: 4
    temp_validity: 1s
    payload: 64B
    etag: 16383
    encoding: raw
    publishers: [fd]
    subscribers: [lan, viz]
)");
  EXPECT_EQ(config.gateway.name, "gw-2");
  EXPECT_EQ(config.gateway.can_node_id, 127);
  EXPECT_EQ(config.gateway.residence_bound, Nanos(250us));
  EXPECT_EQ(config.gateway.control_socket, "/tmp/gw.sock");
  const SegmentSpec& fd = config.segments[0];
  EXPECT_TRUE(fd.can.fd);
  EXPECT_EQ(fd.can.bitrate, BitRate{1'000'000});
  EXPECT_EQ(fd.can.data_bitrate, BitRate{5'000'000});
  EXPECT_DOUBLE_EQ(fd.max_utilization, 0.5);
  EXPECT_EQ(fd.can.errors.max_per_window, 3u);
  EXPECT_EQ(fd.can.errors.window, Nanos(20ms));
  const SegmentSpec& lan = config.segments[1];
  EXPECT_EQ(lan.dds.domain, 7u);
  EXPECT_EQ(lan.latency_bound, Nanos(250us));
  EXPECT_EQ(lan.bandwidth, BitRate{1'000'000'000});
  EXPECT_EQ(lan.reliability, Reliability::best_effort);
  EXPECT_TRUE(lan.realtime);
  EXPECT_EQ(lan.max_message_size, 1024u);
  EXPECT_EQ(lan.dds.interfaces, (std::vector<std::string>{"eth0", "lo"}));
  EXPECT_EQ(lan.dds.discovery_server, "127.0.0.1:11811");
  EXPECT_EQ(config.segments[2].lcm.url, "memq://");
  EXPECT_EQ(config.segments[2].lcm.own_datagrams, LcmOwnDatagrams::cut);
  EXPECT_EQ(config.segments[2].bandwidth, BitRate{10'000'000});
  const ChannelSpec& c = config.channels[0];
  EXPECT_EQ(c.subject, UINT64_MAX);
  EXPECT_EQ(c.cls, ChannelClass::srt);
  EXPECT_EQ(c.period, Nanos(400us));  // 2.5 kHz
  EXPECT_EQ(c.omission_degree, 4u);
  EXPECT_EQ(c.temp_validity, Nanos(1'000'000'000));
  EXPECT_EQ(c.payload, 64u);
  EXPECT_EQ(c.etag, 16383);
  EXPECT_EQ(c.lcm_encoding, LcmEncoding::raw);
}

TEST(Config, FdWithoutDataBitrateUsesNominal) {
  const Config config = parse_ok(R"(
segments:
  - {name: fd, type: can, interface: can0, bitrate: 500kbit/s, fd: true}
  - {name: lan, type: dds}
channels:
  - {name: c, subject: 1, class: nrt, publishers: [fd], subscribers: [lan]}
)");
  EXPECT_EQ(config.segments[0].can.data_bitrate, BitRate{500'000});
}

TEST(Config, MaxRateBecomesPeriod) {
  auto period_of = [](const std::string& rate) {
    const Config config = parse_ok(
        "segments:\n  - {name: a, type: dds}\n  - {name: b, type: lcm}\nchannels:\n"
        "  - {name: c, subject: 1, class: nrt, max_rate: " +
        rate + ", publishers: [a], subscribers: [b]}\n");
    return config.channels.empty() ? std::optional<Nanos>{} : config.channels[0].period;
  };
  EXPECT_EQ(period_of("100Hz"), Nanos(10ms));
  EXPECT_EQ(period_of("20Hz"), Nanos(50ms));
  EXPECT_EQ(period_of("2.5kHz"), Nanos(400us));
  EXPECT_EQ(period_of("1MHz"), Nanos(1us));
  // 1e9 / 3 = 333,333,333.3 ns: rounded down, so the assumed load is never too low.
  EXPECT_EQ(period_of("3Hz"), Nanos(333'333'333));
  EXPECT_EQ(period_of("7Hz"), Nanos(142'857'142));  // 142,857,142.86 ns, not rounded to nearest
  EXPECT_EQ(period_of("0.5Hz"), Nanos(2'000'000'000));
}

// 125 kbit/s, one 8 B frame (1.28 ms) every 10 ms to a 100 us TSN LAN.
std::string fault_config(const std::string& errors) {
  return R"(
gateway: {residence_bound: 100us}
segments:
  - {name: bus, type: can, interface: can0, bitrate: 125kbit/s, errors: )" +
         errors + R"(}
  - {name: lan, type: dds, realtime: true, latency_bound: 100us}
channels:
  - {name: c, subject: 1, class: hrt, period: 10ms, reaction_time: 5ms, payload: 8B, publishers: [bus], subscribers: [lan]}
)";
}

TEST(Config, ZeroErrorsPerWindowDisablesFaultTerm) {
  auto response = [](const std::string& errors) {
    const AdmissionReport report = admit_all(parse_ok(fault_config(errors)));
    return find_hop(report.channels.at(0), "bus")->can->response_time;
  };
  // No fault term: R = C = 1.28 ms.
  EXPECT_EQ(response("{max_per_window: 0}"), Nanos(1280us));
  EXPECT_EQ(response("{max_per_window: 0, window: 10ms}"), Nanos(1280us));
  // One error per 10 ms: + 31 * 8 us + 1.28 ms = + 1.528 ms -> 2.808 ms.
  EXPECT_EQ(response("{max_per_window: 1, window: 10ms}"), Nanos(2808us));
  const Config zero = parse_ok(fault_config("{max_per_window: 0}"));
  EXPECT_EQ(zero.segments[0].can.errors.max_per_window, 0u);
}

TEST(Config, SubjectsInHexOrDecimal) {
  const Config config = parse_ok(R"(
segments: [{name: a, type: dds}, {name: b, type: lcm}]
channels:
  - {name: x, subject: 0x0000000100000042, class: nrt, publishers: [a], subscribers: [b]}
  - {name: y, subject: 4294967363, class: nrt, publishers: [a], subscribers: [b]}
)");
  EXPECT_EQ(config.channels[0].subject, 0x100000042u);
  EXPECT_EQ(config.channels[1].subject, 0x100000043u);
}

// ---------------------------------------------------------------- bind documents

Config running_config() {
  return parse_ok(R"(
segments:
  - {name: bus, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: lan, type: dds}
channels:
  - {name: old, subject: 1, class: nrt, publishers: [bus], subscribers: [lan]}
)");
}

TEST(BindDocument, ChannelsKey) {
  const ChannelsResult r = parse_channels(R"(
channels:
  - {name: a, subject: 10, class: nrt, publishers: [bus], subscribers: [lan]}
  - {name: b, subject: 11, class: srt, period: 10ms, reaction_time: 5ms, publishers: [lan], subscribers: [bus]}
)",
                                          "bind.yaml", running_config());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_EQ(r.channels.size(), 2u);
  EXPECT_EQ(r.channels[0].name, "a");
  EXPECT_EQ(r.channels[1].name, "b");
  EXPECT_EQ(r.channels[1].period, Nanos(10ms));
}

TEST(BindDocument, ListOfChannels) {
  const ChannelsResult r = parse_channels(
      "- {name: a, subject: 10, class: nrt, publishers: [bus], subscribers: [lan]}\n", "bind.yaml", running_config());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_EQ(r.channels[0].subject, 10u);
}

TEST(BindDocument, OneChannelMap) {
  const ChannelsResult r = parse_channels("name: a\nsubject: 10\nclass: nrt\npublishers: [bus]\nsubscribers: [lan]\n",
                                          "bind.yaml", running_config());
  ASSERT_TRUE(r.ok()) << describe(r.errors);
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_EQ(r.channels[0].publishers, std::vector<std::string>{"bus"});
}

TEST(BindDocument, ErrorsWithLocation) {
  // Segments are those of the running configuration.
  ChannelsResult r = parse_channels("name: a\nsubject: 10\nclass: nrt\npublishers: [can9]\nsubscribers: [lan]\n",
                                    "bind.yaml", running_config());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].to_string(),
            "bind.yaml:4:14: channel.publishers[0]: unknown segment 'can9' (one of the segments: bus, lan)");
  EXPECT_TRUE(r.channels.empty());
  // Duplicates inside one bind document.
  r = parse_channels(
      "- {name: a, subject: 10, class: nrt, publishers: [bus], subscribers: [lan]}\n"
      "- {name: a, subject: 10, class: nrt, publishers: [bus], subscribers: [lan]}\n",
      "bind.yaml", running_config());
  ASSERT_EQ(r.errors.size(), 2u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].path, "channels[1].name");
  EXPECT_EQ(r.errors[1].path, "channels[1].subject");
  EXPECT_EQ(r.errors[0].line, 2);
  // Nothing to bind.
  r = parse_channels("[]\n", "bind.yaml", running_config());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_NE(r.errors[0].message.find("no channel to bind"), std::string::npos);
  r = parse_channels("just text\n", "bind.yaml", running_config());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_NE(r.errors[0].message.find("expected channel definitions"), std::string::npos);
  r = parse_channels("channels: []\nsegments: []\n", "bind.yaml", running_config());
  ASSERT_FALSE(r.errors.empty());
  EXPECT_EQ(r.errors[0].path, "segments");
  EXPECT_NE(r.errors[0].message.find("unknown key 'segments'"), std::string::npos);
  r = parse_channels("", "bind.yaml", running_config());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].message.find("empty"), std::string::npos);
}

// A running configuration with IP segments only: lan and lan2 (DDS), viz (LCM).
Config ip_segments() {
  return parse_ok(
      "segments: [{name: lan, type: dds}, {name: lan2, type: dds, domain: 1}, {name: viz, type: lcm}]\nchannels: []\n");
}

TEST(BoundedYaml, AliasAmplificationInABindRequestIsRefusedWithItsLocation) {
  std::string yaml = "a: &a [{name: c, subject: 1, class: nrt, publishers: [lan], subscribers: [viz]}]\n";
  std::string previous = "a";
  for (const char* level : {"b", "c", "d", "e", "f", "g", "h"}) {
    yaml += std::string(level) + ": &" + level + " [";
    for (int i = 0; i < 10; ++i) yaml += (i ? ", *" : "*") + previous;
    yaml += "]\n";
    previous = level;
  }
  yaml += "channels: *h\n";
  ASSERT_LT(yaml.size(), 1000u);
  const auto r = parse_channels(yaml, "bind.yaml", ip_segments());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_NE(r.errors[0].message.find("aliases expand the document beyond"), std::string::npos);
  EXPECT_GT(r.errors[0].line, 1);
  EXPECT_TRUE(r.channels.empty());
}

// yaml-cpp's event parser yields empty documents without end after a leading ',': the loader
// reads the first document only, so this is "empty" at once, not 2,000,000 counted nodes (found
// by fuzz_control as a 100-byte bind request taking 10 s under ASan).
TEST(BoundedYaml, EndlessEmptyDocumentsAreNotCounted) {
  const std::string yaml = ",{ anra, subje888n*me~xtra, subje8888888sube:a,,,,,subj}";
  const auto r = parse_channels(yaml, "bind.yaml", ip_segments());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].message.find("nodes"), std::string::npos) << r.errors[0].message;
  EXPECT_NE(r.errors[0].message.find("empty"), std::string::npos) << r.errors[0].message;
  EXPECT_TRUE(r.channels.empty());
}

TEST(BoundedYaml, ErrorsBeyondTheLimitAreCountedInOneLine) {
  std::string yaml = "segments: [{name: lan, type: dds}, {name: viz, type: lcm}]\nchannels:\n";
  for (int i = 0; i < 250; ++i)
    yaml += "  - {name: c" + std::to_string(i) + ", subject: 0, class: nrt, publishers: [lan], subscribers: [viz]}\n";
  const auto r = parse_config(yaml, "many.yaml");
  ASSERT_EQ(r.errors.size(), 101u);
  EXPECT_EQ(r.errors[99].path, "channels[99].subject");
  EXPECT_EQ(r.errors[100].message, "150 more error(s) not shown");
}

TEST(BoundedYaml, ALargeFileWithinTheLimitsStillLoads) {
  std::string yaml = "segments: [{name: lan, type: dds}, {name: viz, type: lcm}]\nchannels:\n";
  const std::string comment = "  # " + std::string(200, '-') + "\n";  // bytes without nodes: parsing stays quick
  for (int i = 1; i <= 4000; ++i) {                                   // above 1 MiB: the node count runs too
    yaml += comment + "  - {name: channel_number_" + std::to_string(i) + ", subject: " + std::to_string(i) +
            ", class: nrt, publishers: [lan], subscribers: [viz]}\n";
  }
  ASSERT_GT(yaml.size(), 1u << 20);
  const auto r = parse_config(yaml, "large.yaml");
  EXPECT_TRUE(r.ok()) << describe(r.errors);
  EXPECT_EQ(r.config.channels.size(), 4000u);
  EXPECT_FALSE(parse_config(std::string(9u << 20, '#'), "huge.yaml").ok());
}

TEST(Quantities, MaxRateBecomesAPeriodWithoutOverflow) {
  const auto slowest = parse_channels(
      "{name: c, subject: 1, class: nrt, max_rate: 0.000000001Hz, publishers: [lan], subscribers: [viz]}", "bind.yaml",
      ip_segments());
  ASSERT_TRUE(slowest.ok()) << describe(slowest.errors);
  ASSERT_TRUE(slowest.channels[0].period);
  EXPECT_GT(*slowest.channels[0].period, Nanos(999'999'999'000'000'000));  // 1e9 s, give or take rounding
  EXPECT_LE(*slowest.channels[0].period, Nanos(1'000'000'000'000'000'000));
  EXPECT_EQ(period_of_rate(1e9), Nanos(1));
  EXPECT_EQ(period_of_rate(3.0), Nanos(333'333'333));
}

TEST(Quantities, ALongLcmNameIsRefusedOnlyWhereLcmCarriesIt) {
  const std::string name(64, 'n');
  const auto over_dds =
      parse_channels("{name: " + name + ", subject: 1, class: nrt, publishers: [lan], subscribers: [lan2]}",
                     "bind.yaml", ip_segments());
  const auto over_lcm =
      parse_channels("{name: " + name + ", subject: 1, class: nrt, publishers: [lan], subscribers: [viz]}", "bind.yaml",
                     ip_segments());
  EXPECT_FALSE(over_lcm.ok());
  EXPECT_NE(describe(over_lcm.errors).find("at most 63 characters"), std::string::npos) << describe(over_lcm.errors);
  EXPECT_TRUE(over_dds.ok()) << describe(over_dds.errors);
}

// cosmicd's reload source: an unchanged file is not parsed again; any change, a broken file or
// another path is.
TEST(ConfigFileLoader, OnlyAnUnchangedValidFileSkipsParsing) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/cosmic_loader_test.yaml";
  const std::string other = dir + "/cosmic_loader_test_other.yaml";
  const std::string one =
      "segments: [{name: lan, type: dds}, {name: viz, type: lcm}]\nchannels:\n"
      "  - {name: a, subject: 1, class: nrt, publishers: [lan], subscribers: [viz]}\n";
  auto write = [](const std::string& file, const std::string& text) { std::ofstream(file, std::ios::trunc) << text; };
  write(path, one);
  write(other, one);
  ConfigFileLoader loader;
  const ConfigResult first = loader.load(path);
  ASSERT_TRUE(first.ok()) << describe(first.errors);
  EXPECT_FALSE(loader.last_was_unchanged());
  const ConfigResult again = loader.load(path);
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(loader.last_was_unchanged());
  ASSERT_EQ(again.config.channels.size(), 1u);
  EXPECT_EQ(again.config.channels[0], first.config.channels[0]);
  EXPECT_EQ(again.config.segments, first.config.segments);

  loader.load(other);  // same bytes, another file: parsed (errors would name that file)
  EXPECT_FALSE(loader.last_was_unchanged());

  write(path, one + "  - {name: b, subject: 2, class: nrt, publishers: [viz], subscribers: [lan]}\n");
  const ConfigResult changed = loader.load(path);
  ASSERT_TRUE(changed.ok()) << describe(changed.errors);
  EXPECT_FALSE(loader.last_was_unchanged());
  EXPECT_EQ(changed.config.channels.size(), 2u);

  write(path, one + "  - {name: b, subject: two}\n");
  const ConfigResult broken = loader.load(path);
  EXPECT_FALSE(broken.ok());
  EXPECT_FALSE(loader.last_was_unchanged());
  write(path, one);
  EXPECT_TRUE(loader.load(path).ok());
  EXPECT_FALSE(loader.last_was_unchanged());  // parsed: a failed load forgets the remembered file

  std::remove(other.c_str());
  std::remove(path.c_str());
  const ConfigResult gone = loader.load(path);
  EXPECT_FALSE(gone.ok());
  EXPECT_FALSE(loader.last_was_unchanged());
}

}  // namespace
}  // namespace cosmic

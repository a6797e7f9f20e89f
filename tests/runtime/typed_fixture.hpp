// The typed-channel gateway fixture (issue 35) shared by typed_forwarding_test.cpp and
// typed_admission_test.cpp: a gateway over in-memory segments body (CAN), lan (DDS), viz (LCM) and
// chassis (CAN), its DBC, LCM and configuration texts, and the helpers that read what it sent and
// counted.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic::typed_test {

class TypedTestLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override { lines.emplace_back(message); }
  std::vector<std::string> lines;
};

// Speed: float64 (raw 16 bits x 0.01), Gear: int8, Valid: bool; Torque: float64 (raw 8 bits x 2.5,
// 0..637.5 Nm), Mode: uint8.
inline constexpr const char* kWheelDbc = R"(VERSION ""
NS_ :
BS_:
BU_: Ecu Gateway
BO_ 416 WheelSpeed: 4 Ecu
 SG_ Speed : 0|16@1+ (0.01,0) [0|655.35] "km/h" Gateway
 SG_ Gear : 16|8@1- (1,0) [-1|6] "" Gateway
 SG_ Valid : 24|1@1+ (1,0) [0|1] "" Gateway
BO_ 512 DriveCommand: 2 Gateway
 SG_ Torque : 0|8@1+ (2.5,0) [0|637.5] "Nm" Ecu
 SG_ Mode : 8|8@1+ (1,0) [0|255] "" Ecu
BO_ 432 BrakeStatus: 4 Ecu
 SG_ Crc : 0|8@1+ (1,0) [0|255] "" Gateway
 SG_ Counter : 8|4@1+ (1,0) [0|14] "" Gateway
 SG_ Pressure : 16|16@1+ (1,0) [0|65535] "bar" Gateway
BO_ 433 BrakeCommand: 4 Gateway
 SG_ Crc : 0|8@1+ (1,0) [0|255] "" Ecu
 SG_ Counter : 8|4@1+ (1,0) [0|14] "" Ecu
 SG_ Pressure : 16|16@1+ (1,0) [0|65535] "bar" Ecu
)";

// The signal gateway's far side (another bus's DBC): VehicleSpeed carries wheel's Speed (12 bits x
// 0.2), Gear (as GearPos, 4 bits signed) and Valid; NarrowSpeed the same fields by their names, its
// Speed in 8 bits (0..51 km/h, narrower than wheel's 0..655.35).
inline constexpr const char* kChassisDbc = R"(VERSION ""
BO_ 768 VehicleSpeed: 3 Gateway
 SG_ VehicleSpeed : 0|12@1+ (0.2,0) [0|819] "km/h" Cluster
 SG_ GearPos : 12|4@1- (1,0) [-1|6] "" Cluster
 SG_ Valid : 16|1@1+ (1,0) [0|1] "" Cluster
BO_ 769 NarrowSpeed: 2 Gateway
 SG_ Speed : 0|8@1+ (0.2,0) [0|51] "km/h" Cluster
 SG_ Gear : 8|4@1- (1,0) [-1|6] "" Cluster
 SG_ Valid : 12|1@1+ (1,0) [0|1] "" Cluster
)";

inline constexpr const char* kPoseLcm = R"(package demo;
struct pose_t {
  int64_t stamp;
  int8_t flags;
  double xy[2];
  int16_t n;
  float ranges[n];
}
)";

inline std::string typed_config(const std::string& on_range) {
  return R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
  - {name: chassis, type: can, interface: can1, bitrate: 500kbit/s}
channels:
  - name: wheel
    subject: 0x10
    class: srt
    period: 10ms
    reaction_time: 50ms
    type: {dbc: wheel.dbc, message: WheelSpeed}
    publishers: [body]
    subscribers: [lan, viz, chassis]
    native:
      body: {can_id: 0x1A0}
      viz: {channel: WHEEL, representation: json}
      chassis: {dbc: chassis.dbc, message: VehicleSpeed, map: {Speed: VehicleSpeed, Gear: GearPos}}
  - name: drive
    subject: 0x11
    class: nrt
    type: {dbc: wheel.dbc, message: DriveCommand}
    on_range: )" +
         on_range + R"(
    publishers: [lan]
    subscribers: [body]
    native: {body: {can_id: 0x200}}
  - name: pose
    subject: 0x12
    class: nrt
    type: {lcm: pose.lcm, name: demo.pose_t, max_length: {ranges: 4}}
    publishers: [viz]
    subscribers: [lan]
    native: {viz: {channel: POSE}, lan: {topic: rt/pose, type: "demo::pose_t"}}
  - name: brake
    subject: 0x13
    class: nrt
    omission_degree: 1
    type: {dbc: wheel.dbc, message: BrakeStatus, e2e: {counter: Counter, crc: Crc, data_id: 0x0123}}
    publishers: [body]
    subscribers: [lan]
    native: {body: {can_id: 0x1B0}}
  - name: brake_command
    subject: 0x14
    class: nrt
    type: {dbc: wheel.dbc, message: BrakeCommand, e2e: {counter: Counter, crc: Crc, data_id: 0x0124, data_id_mode: low}}
    publishers: [lan]
    subscribers: [body]
    native: {body: {can_id: 0x1B1}}
)";
}

inline void put_le(std::vector<std::uint8_t>& out, const void* value, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(value);
  out.insert(out.end(), bytes, bytes + size);  // this test runs on little-endian hosts only
}
inline void put_be(std::vector<std::uint8_t>& out, std::uint64_t value, std::size_t size) {
  for (std::size_t i = size; i-- > 0;) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
template <typename T>
std::uint64_t bits_of(T value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof value);
  return bits;
}

class TypedForwardingTest : public ::testing::Test {
 protected:
  TypedForwardingTest()
      : dir_(std::filesystem::temp_directory_path() /
             ("cosmic-typed-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name())),
        gateway(
            [this](const SegmentSpec& spec, const GatewayIdentity&, Logger&) -> std::unique_ptr<SegmentAdapter> {
              auto adapter = std::make_unique<MemoryAdapter>(spec.name);
              adapters[spec.name] = adapter.get();
              return adapter;
            },
            log, 0x4321) {
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "wheel.dbc") << kWheelDbc;
    std::ofstream(dir_ / "pose.lcm") << kPoseLcm;
    std::ofstream(dir_ / "chassis.dbc") << kChassisDbc;
  }
  ~TypedForwardingTest() override {
    gateway.stop();
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  ConfigResult load(const std::string& text) {
    std::ofstream(dir_ / "gw.yaml") << text;
    return parse_config(text, (dir_ / "gw.yaml").string());
  }

  void start(const std::string& on_range = "drop") {
    ConfigResult loaded = load(typed_config(on_range));
    ASSERT_TRUE(loaded.ok()) << (loaded.errors.empty() ? "" : loaded.errors[0].to_string());
    ASSERT_TRUE(gateway.start(std::move(loaded.config)).applied);
  }

  // The payload of the `index`-th event sent on `segment`, once it is there.
  std::vector<std::uint8_t> sent_on(const std::string& segment, std::size_t index) {
    EXPECT_GT(adapters[segment]->wait_sent(index + 1, std::chrono::seconds(5)), index) << segment;
    const auto sent = adapters[segment]->sent();
    return sent.size() > index ? sent[index].payload : std::vector<std::uint8_t>{};
  }

  std::uint64_t dropped(const std::string& channel, const std::string& segment, DropReason reason) const {
    for (const auto& c : gateway.channel_stats()) {
      if (c.name != channel) continue;
      for (const auto& s : c.segments) {
        if (s.segment == segment) return s.dropped[static_cast<std::size_t>(reason)];
      }
    }
    return ~std::uint64_t{0};
  }

  const SegmentCountersSnapshot* hop(const std::vector<ChannelStatsSnapshot>& stats, const std::string& channel,
                                     const std::string& segment) const {
    for (const auto& c : stats) {
      for (const auto& s : c.segments) {
        if (c.name == channel && s.segment == segment) return &s;
      }
    }
    return nullptr;
  }

  std::filesystem::path dir_;
  TypedTestLogger log;
  std::map<std::string, MemoryAdapter*> adapters;
  Gateway gateway;
};

// The configuration `channels` (a YAML list) with a CAN segment body and an LCM segment viz,
// read next to wheel.dbc.
inline ConfigResult parse_with_wheel_dbc(const std::string& channels) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("cosmic-typed-config-" + std::to_string(::getpid()) + "-" +
                                                ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "wheel.dbc") << kWheelDbc;
  const std::string text = R"(
gateway: {name: gw, can_node_id: 1}
segments:
  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
)" + channels;
  ConfigResult result = parse_config(text, (dir / "gw.yaml").string());
  std::filesystem::remove_all(dir);
  return result;
}

}  // namespace cosmic::typed_test

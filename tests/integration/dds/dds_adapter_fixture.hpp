// Helpers shared by the DDS adapter integration tests (dds_adapter_test.cpp,
// dds_adapter_reconfig_test.cpp): the segment and channel builders, the cosmic-dds-peer command
// line and its diagnostic lines, starting a peer publisher once both sides matched, the adapter
// Fixture and the outbound events the tests send.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/build_paths.hpp"
#include "cosmic/dds_adapter.hpp"
#include "test_support.hpp"

namespace cosmic::dds_test {

using namespace std::chrono_literals;
using json = nlohmann::json;
using test::Child;
using test::RecordingSink;

inline constexpr std::uint64_t kSelfId = 0xC05A1C0001ULL;
inline constexpr auto kWait = 20s;

inline GatewayIdentity self_identity() { return GatewayIdentity{kSelfId, "gw-test"}; }

inline SegmentSpec dds_segment(std::uint32_t domain, Reliability reliability = Reliability::reliable) {
  SegmentSpec s;
  s.name = "dds" + std::to_string(domain);
  s.type = SegmentType::dds;
  s.reliability = reliability;
  s.dds.domain = domain;
  return s;
}

inline ChannelBinding binding(ChannelId id, const std::string& name, HopRole role, std::uint32_t omission_degree = 2) {
  ChannelBinding b;
  b.id = id;
  b.role = role;
  b.spec.name = name;
  b.spec.subject = 0x5100 + id;
  b.spec.omission_degree = omission_degree;
  b.spec.payload = 64;
  return b;
}

inline std::vector<std::string> peer(std::vector<std::string> args) {
  args.insert(args.begin(), cosmic::build_paths::dds_peer);
  return args;
}

inline std::uint8_t pattern(std::uint64_t q, std::uint64_t i) { return static_cast<std::uint8_t>((q * 7 + i) & 0xff); }

inline std::string hex(const std::vector<std::uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (auto b : bytes) {
    out.push_back(digits[b >> 4]);
    out.push_back(digits[b & 0xf]);
  }
  return out;
}

inline json parse(const std::string& line) { return json::parse(line, nullptr, false); }

// A stderr diagnostic line of the peer with the given "event".
inline std::function<bool(const std::string&)> diag_event(const std::string& event) {
  return [event](const std::string& line) {
    const json j = parse(line);
    return j.is_object() && j.value("event", "") == event;
  };
}
inline std::function<bool(const std::string&)> matched_at_least(int n) {
  return [n](const std::string& line) {
    const json j = parse(line);
    return j.is_object() && j.value("event", "") == "matched" && j.value("count", 0) >= n;
  };
}

// Spawns a peer publisher (with --start-on-stdin) and lets it publish once its writer matched
// and `ready` holds: our side matched it too (a reader drops what a writer sends before).
inline std::unique_ptr<Child> start_pub(std::vector<std::string> args, const std::function<bool()>& ready) {
  args.push_back("--start-on-stdin");
  auto pub = std::make_unique<Child>(peer(std::move(args)));
  EXPECT_TRUE(pub->wait_err(diag_event("waiting_for_start"), kWait)) << pub->describe();
  EXPECT_TRUE(test::eventually(ready, kWait)) << pub->describe();
  pub->send_line("go");
  return pub;
}

struct Fixture {
  explicit Fixture(SegmentSpec segment, std::uint64_t id = kSelfId)
      : spec(std::move(segment)), adapter(make_dds_segment_adapter(spec, GatewayIdentity{id, "gw-test"}, log)) {}
  test::StderrLogger log;
  SegmentSpec spec;
  RecordingSink sink;
  std::unique_ptr<DdsSegmentAdapter> adapter;

  bool matched(ChannelId id, HopRole role, std::size_t n = 1) {
    return test::eventually([&] { return adapter->matched_endpoints(id, role) >= n; }, kWait);
  }
  std::function<bool()> reader_matched(ChannelId id, std::size_t n = 1) {
    return [this, id, n] { return adapter->matched_endpoints(id, HopRole::publisher) >= n; };
  }
};

inline OutboundEvent outbound(ChannelId channel, std::uint32_t q, std::vector<std::uint8_t>& storage,
                              std::uint64_t origin = kSelfId, std::size_t size = 16) {
  storage.resize(size);
  for (std::size_t i = 0; i < size; ++i) storage[i] = pattern(q, i);
  OutboundEvent ev;
  ev.channel = channel;
  ev.header.subject = 0xABCDEF;
  ev.header.origin = origin;
  ev.header.sequence = q;
  ev.header.hop_count = 1;
  ev.header.created_ns = 1'000'000 + q;
  ev.header.age_ns = 1000 * q;
  ev.payload = storage;
  return ev;
}

}  // namespace cosmic::dds_test

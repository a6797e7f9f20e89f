// gateway.federation and the segment key `network` (docs/yaml-reference.md): what is accepted,
// and every mistake with its location and key path.
#include <gtest/gtest.h>

#include "config_test_support.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

std::string document(const std::string& federation, const std::string& extra_segment = "") {
  return "gateway:\n  name: gw1\n" + federation +
         "segments:\n"
         "  - {name: lan, type: dds, domain: 3, network: backbone}\n"
         "  - {name: body, type: can, interface: can0, bitrate: 500kbit/s, network: body-bus}\n" +
         extra_segment + "channels: []\n";
}

TEST(FederationConfig, ReadsTheSegmentTheLeaseAndNetworkNames) {
  const ConfigResult r = parse_config(document("  federation: {segment: lan, lease: 2s}\n"), "g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  EXPECT_TRUE(r.config.gateway.federation.enabled());
  EXPECT_EQ(r.config.gateway.federation.segment, "lan");
  EXPECT_EQ(r.config.gateway.federation.lease, Nanos(2s));
  EXPECT_EQ(r.config.segments[0].network, "backbone");
  EXPECT_EQ(r.config.segments[1].network, "body-bus");
  const ConfigResult off = parse_config(document(""), "g.yaml");
  ASSERT_TRUE(off.ok()) << test::errors_text(off);
  EXPECT_FALSE(off.config.gateway.federation.enabled());
  EXPECT_EQ(off.config.gateway.federation.lease, Nanos(3s));
}

TEST(FederationConfig, EveryMistakeIsReportedWithItsPlace) {
  struct Case {
    std::string federation;
    std::string extra;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"  federation: {segment: wan}\n", "",
       "g.yaml:3:25: gateway.federation.segment: unknown segment 'wan' (a DDS segment: lan)"},
      {"  federation: {segment: body}\n", "", "gateway.federation.segment: segment 'body' is can"},
      {"  federation: {lease: 2s}\n", "", "gateway.federation.segment: missing required key 'segment'"},
      {"  federation: {segment: lan, lease: 10ms}\n", "",
       "gateway.federation.lease: lease out of range (from 100ms to 1h"},
      {"  federation: {segment: lan, lease: forever}\n", "", "gateway.federation.lease"},
      {"  federation: {segment: lan, domain: 3}\n", "", "gateway.federation.domain"},
      {"  federation: {segment: lan, claim_window: 50ms}\n", "",
       "gateway.federation.claim_window: claim_window out of range (from 300ms"},
      {"  federation: {segment: lan, peers: [CN=gw2]}\n", "",
       "g.yaml:3:37: gateway.federation.peers: peers needs a secure federation segment: segment 'lan' has no "
       "security, so no peer's subject can be authenticated (give segment lan a security: section"},
      {"  federation: {segment: lan, peers: CN=gw2}\n", "", "gateway.federation.peers"},
      {"", "  - {name: body2, type: can, interface: can1, bitrate: 500kbit/s, network: body-bus}\n",
       "segments[2].network: segment 'body2' attaches the same network as segment 'body'"},
  };
  for (const Case& c : cases) {
    const ConfigResult r = parse_config(document(c.federation, c.extra), "g.yaml");
    test::expect_refused_with(r, c.expected);
  }
}

}  // namespace
}  // namespace cosmic

// gateway.metrics: off by default, loopback unless allow_remote, every mistake located.
#include <gtest/gtest.h>

#include <string>

#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

std::string with_gateway(const std::string& gateway_lines) {
  return "gateway:\n" + gateway_lines +
         "segments:\n"
         "  - {name: lan, type: dds, domain: 0}\n"
         "channels: []\n";
}

ConfigResult parse(const std::string& gateway_lines) { return parse_config(with_gateway(gateway_lines), "m.yaml"); }

std::string errors_of(const ConfigResult& result) {
  std::string out;
  for (const auto& e : result.errors) out += e.to_string() + "\n";
  return out;
}

TEST(MetricsConfig, OffByDefault) {
  const auto result = parse("  name: gw\n");
  ASSERT_TRUE(result.ok()) << errors_of(result);
  EXPECT_FALSE(result.config.gateway.metrics.enabled);
}

TEST(MetricsConfig, LoopbackIpv4) {
  const auto result = parse("  metrics: {listen: 127.0.0.1:9877}\n");
  ASSERT_TRUE(result.ok()) << errors_of(result);
  const MetricsSpec& m = result.config.gateway.metrics;
  EXPECT_TRUE(m.enabled);
  EXPECT_EQ(m.host, "127.0.0.1");
  EXPECT_EQ(m.port, 9877);
  EXPECT_FALSE(m.allow_remote);
}

TEST(MetricsConfig, LoopbackIpv6AndLocalhost) {
  const auto v6 = parse("  metrics: {listen: \"[::1]:9100\"}\n");
  ASSERT_TRUE(v6.ok()) << errors_of(v6);
  EXPECT_EQ(v6.config.gateway.metrics.host, "::1");
  EXPECT_EQ(v6.config.gateway.metrics.port, 9100);
  const auto name = parse("  metrics: {listen: localhost:9101}\n");
  ASSERT_TRUE(name.ok()) << errors_of(name);
  EXPECT_EQ(name.config.gateway.metrics.host, "127.0.0.1");
}

TEST(MetricsConfig, RemoteNeedsExplicitConsent) {
  const auto refused = parse("  metrics: {listen: 0.0.0.0:9877}\n");
  ASSERT_EQ(refused.errors.size(), 1u) << errors_of(refused);
  EXPECT_EQ(refused.errors[0].to_string(),
            "m.yaml:2:21: gateway.metrics.listen: '0.0.0.0:9877' is not a loopback address "
            "(127.0.0.1:PORT or [::1]:PORT, or allow_remote: true to serve other hosts)");
  const auto allowed = parse("  metrics: {listen: 0.0.0.0:9877, allow_remote: true}\n");
  ASSERT_TRUE(allowed.ok()) << errors_of(allowed);
  EXPECT_EQ(allowed.config.gateway.metrics.host, "0.0.0.0");
  EXPECT_TRUE(allowed.config.gateway.metrics.allow_remote);
}

TEST(MetricsConfig, BadAddressesAreLocated) {
  const auto result = parse(
      "  metrics:\n"
      "    listen: 9877\n"
      "    allow_remote: yes\n");
  ASSERT_EQ(result.errors.size(), 2u) << errors_of(result);
  EXPECT_EQ(result.errors[0].to_string(),
            "m.yaml:4:19: gateway.metrics.allow_remote: 'yes' is not a boolean (true or false)");
  EXPECT_EQ(result.errors[1].to_string(),
            "m.yaml:3:13: gateway.metrics.listen: '9877' has no port (IP:PORT such as 127.0.0.1:9877 or [::1]:9877)");
}

TEST(MetricsConfig, PortAndHostChecked) {
  EXPECT_NE(errors_of(parse("  metrics: {listen: 127.0.0.1:70000}\n")).find("has no port from 1 to 65535"),
            std::string::npos);
  EXPECT_NE(errors_of(parse("  metrics: {listen: 127.0.0.1:0}\n")).find("has no port from 1 to 65535"),
            std::string::npos);
  EXPECT_NE(
      errors_of(parse("  metrics: {listen: \"::1:9877\"}\n")).find("has no IP address as host (IPv6 goes in brackets)"),
      std::string::npos);
  EXPECT_NE(errors_of(parse("  metrics: {listen: gateway.example:9877}\n")).find("has no IP address"),
            std::string::npos);
}

TEST(MetricsConfig, ListenIsRequiredAndKeysAreKnown) {
  const auto missing = parse("  metrics: {allow_remote: true}\n");
  ASSERT_EQ(missing.errors.size(), 1u) << errors_of(missing);
  EXPECT_NE(missing.errors[0].to_string().find("gateway.metrics.listen: missing required key 'listen'"),
            std::string::npos);
  const auto unknown = parse("  metrics: {listen: 127.0.0.1:9877, port: 9877}\n");
  ASSERT_EQ(unknown.errors.size(), 1u) << errors_of(unknown);
  EXPECT_NE(unknown.errors[0].to_string().find("unknown key 'port'"), std::string::npos);
}

}  // namespace
}  // namespace cosmic

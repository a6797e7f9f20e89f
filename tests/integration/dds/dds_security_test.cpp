// DDS Security on a DDS segment (issue 36, item 1; docs/security.md) over real Fast DDS in a network
// namespace, with a test PKI the openssl command line makes here (tests/support/make_test_pki.sh):
// two gateways' adapters, each with its own identity, authenticate and exchange a channel both
// ways; a participant without security (cosmic-dds-peer, plain Fast DDS) on the same domain never
// receives a sample of it and is counted once as unauthenticated; an authenticated gateway cannot
// publish a topic its permissions do not grant; the federation's links take announcements only from
// the gateways gateway.federation.peers lists, by the subject their authenticated GUID proves.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "cosmic/build_paths.hpp"
#include "cosmic/certificate_subject.hpp"
#include "cosmic/dds_federation_link.hpp"
#include "dds_adapter_fixture.hpp"

namespace cosmic::dds_test {
namespace {

class DdsSecurityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    pki_ = std::filesystem::path(testing::TempDir()) / ("dds_security_" + std::to_string(::getpid()));
    const std::string command =
        std::string(cosmic::build_paths::source_dir) + "/tests/support/make_test_pki.sh " + pki_.string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(pki_); }

  static SegmentSpec secure_segment(std::uint32_t domain, const std::string& identity) {
    SegmentSpec s = dds_segment(domain);
    DdsSecuritySpec security;
    security.identity_ca = (pki_ / "identity_ca.pem").string();
    security.certificate = (pki_ / (identity + "_cert.pem")).string();
    security.private_key = (pki_ / (identity + "_key.pem")).string();
    security.permissions_ca = (pki_ / "permissions_ca.pem").string();
    security.governance = (pki_ / "governance.p7s").string();
    security.permissions = (pki_ / "permissions.p7s").string();
    security.subject = "/O=cosmic/CN=" + identity;
    s.dds.security = security;
    return s;
  }

  static std::filesystem::path pki_;
};

std::filesystem::path DdsSecurityTest::pki_;

TEST_F(DdsSecurityTest, AuthenticatedGatewaysExchangeAndAPlainParticipantReceivesNothing) {
  constexpr std::uint32_t kDomain = 61;
  Fixture a(secure_segment(kDomain, "gateway-a"), 0xA1);
  Fixture b(secure_segment(kDomain, "gateway-b"), 0xB2);
  ASSERT_TRUE(a.adapter->start(a.sink).ok);
  ASSERT_TRUE(b.adapter->start(b.sink).ok);
  // obstacle: a sends, b receives; drive: b sends, a receives.
  ASSERT_TRUE(a.adapter
                  ->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::subscriber),
                                                          binding(2, "drive", HopRole::publisher)})
                  .ok);
  ASSERT_TRUE(b.adapter
                  ->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::publisher),
                                                          binding(2, "drive", HopRole::subscriber)})
                  .ok);
  // A plain Fast DDS participant on the same domain and topic, waiting for one sample.
  test::Child plain(
      peer({"sub", "--domain", std::to_string(kDomain), "--channel", "obstacle", "--count", "1", "--timeout", "6"}));
  // The handshake (PKI-DH) comes first; a failed one is retried every second.
  ASSERT_TRUE(a.matched(1, HopRole::subscriber)) << "gateway-a's writer never matched gateway-b's reader";
  ASSERT_TRUE(b.matched(2, HopRole::subscriber)) << "gateway-b's writer never matched gateway-a's reader";
  std::vector<std::uint8_t> storage;
  std::uint32_t q = 0;
  ASSERT_TRUE(test::eventually(
      [&] {
        a.adapter->send(outbound(1, ++q, storage, 0xA1));
        return b.sink.count_on(1) >= 3;
      },
      kWait));
  ASSERT_TRUE(test::eventually(
      [&] {
        b.adapter->send(outbound(2, ++q, storage, 0xB2));
        return a.sink.count_on(2) >= 3;
      },
      kWait));
  const auto received = b.sink.events_on(1);
  EXPECT_EQ(received.front().payload.size(), 16u);
  EXPECT_EQ(received.front().header.origin, 0xA1u);
  // Obstacles keep flowing for the plain participant's whole wait (it has time to discover
  // gateway-a's writer, were it visible to it); it gives up without a sample (exit 1 on its timeout).
  std::optional<int> plain_exit;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!plain_exit && std::chrono::steady_clock::now() < deadline) {
    a.adapter->send(outbound(1, ++q, storage, 0xA1));
    plain_exit = plain.wait_exit(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(plain_exit.has_value());
  EXPECT_EQ(*plain_exit, 1) << "a participant without security received an authenticated gateway's sample";
  EXPECT_TRUE(plain.out_lines().empty());
  // Fast DDS 2.9.1 reports the plain participant as refused authentication, to each of a's
  // participants: counted once, with its GUID (a plain participant's prefix starts 01.0f).
  ASSERT_TRUE(test::eventually(
      [&] { return a.adapter->statistics().transport_counter("unauthenticated").value_or(0) >= 1; }, kWait));
  const AdapterStatistics stats = a.adapter->statistics();
  EXPECT_EQ(stats.transport_counter("unauthenticated"), 1u) << "one plain participant, counted once";
  ASSERT_EQ(stats.transport_notes.size(), 1u);
  EXPECT_EQ(stats.transport_notes.front().name, "last_unauthenticated");
  EXPECT_EQ(stats.transport_notes.front().text.rfind("01.0f.", 0), 0u) << stats.transport_notes.front().text;
  EXPECT_EQ(b.adapter->statistics().transport_counter("unauthenticated").value_or(0), 1u);
  EXPECT_FALSE(Fixture(dds_segment(kDomain), 0xD4).adapter->statistics().transport_counter("unauthenticated"))
      << "a segment without security counts no such thing";
  a.adapter->stop();
  b.adapter->stop();
}

// gateway-c is authenticated, but its permissions grant it only cosmic/telemetry to publish: a
// channel it would send on any other topic is refused at bind with the reason, the others bind.
TEST_F(DdsSecurityTest, AnAuthenticatedGatewayCannotPublishWhatItsPermissionsDoNotGrant) {
  Fixture c(secure_segment(62, "gateway-c"), 0xC3);
  ASSERT_TRUE(c.adapter->start(c.sink).ok);
  const Status status = c.adapter->configure(std::vector<ChannelBinding>{binding(1, "obstacle", HopRole::subscriber),
                                                                         binding(2, "telemetry", HopRole::subscriber),
                                                                         binding(3, "drive", HopRole::publisher)});
  ASSERT_FALSE(status.ok);
  EXPECT_NE(status.error.find("cannot create a DataWriter on cosmic/obstacle (a secure segment: do the permissions "
                              "grant /O=cosmic/CN=gateway-c to publish it?)"),
            std::string::npos)
      << status.error;
  EXPECT_EQ(status.error.find("telemetry"), std::string::npos) << status.error;
  EXPECT_EQ(status.error.find("drive"), std::string::npos) << status.error;
  c.adapter->stop();
}

// gateway-a lists gateway-b only; gateway-c authenticates too (its permissions let it publish
// cosmic/federation) but is not listed: its announcement arrives refused, naming the subject its
// GUID proves; gateway-b's arrives with its subject. Without a list every authenticated gateway
// counts, with the subject its GUID proves.
TEST_F(DdsSecurityTest, TheFederationTakesOnlyListedGatewaysByTheSubjectTheyAuthenticatedWith) {
  constexpr std::uint32_t kDomain = 63;
  test::StderrLogger log;
  FederationSpec listing_b;
  listing_b.segment = "backbone";
  listing_b.lease = std::chrono::seconds(1);
  auto subject = parse_certificate_subject("CN=gateway-b,O=cosmic");
  ASSERT_TRUE(subject);
  listing_b.peers.push_back(FederationPeerSpec{subject.value().text, subject.value().prefixes});
  FederationSpec open = listing_b;
  open.peers.clear();
  auto a = make_dds_federation_link(secure_segment(kDomain, "gateway-a"), GatewayIdentity{0xA, "a"}, listing_b, log);
  auto b = make_dds_federation_link(secure_segment(kDomain, "gateway-b"), GatewayIdentity{0xB, "b"}, open, log);
  auto c = make_dds_federation_link(secure_segment(kDomain, "gateway-c"), GatewayIdentity{0xC, "c"}, open, log);
  ASSERT_EQ(a->start(), "");
  ASSERT_EQ(b->start(), "");
  ASSERT_EQ(c->start(), "");
  ASSERT_TRUE(a->publish(0xA, "a's"));
  ASSERT_TRUE(b->publish(0xB, "b's"));
  ASSERT_TRUE(c->publish(0xC, "c's"));
  std::map<std::uint64_t, FederationMessage> at_a;
  std::map<std::uint64_t, FederationMessage> at_b;
  auto heard = [](FederationLink& link, std::map<std::uint64_t, FederationMessage>& out, std::size_t count) {
    return test::eventually(
        [&] {
          for (FederationMessage& m : link.take()) {
            if (m.kind == FederationMessage::Kind::announcement) out[m.key] = std::move(m);
          }
          return out.size() >= count;
        },
        std::chrono::seconds(30));
  };
  ASSERT_TRUE(heard(*a, at_a, 2)) << "gateway-a heard " << at_a.size() << " announcements";
  EXPECT_EQ(at_a[0xB].subject, "/O=cosmic/CN=gateway-b");
  EXPECT_EQ(at_a[0xB].refusal, "");
  EXPECT_EQ(at_a[0xC].subject, "");
  EXPECT_NE(at_a[0xC].refusal.find(" authenticated as /O=cosmic/CN=gateway-c, which gateway.federation.peers does "
                                   "not list"),
            std::string::npos)
      << at_a[0xC].refusal;
  ASSERT_TRUE(heard(*b, at_b, 2)) << "gateway-b heard " << at_b.size() << " announcements";
  EXPECT_EQ(at_b[0xA].subject, "/O=cosmic/CN=gateway-a");
  EXPECT_EQ(at_b[0xC].subject, "/O=cosmic/CN=gateway-c");
  EXPECT_EQ(at_b[0xC].refusal, "");
}

}  // namespace
}  // namespace cosmic::dds_test

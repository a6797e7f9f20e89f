// A DDS segment's `security:` (docs/security.md): the six files checked at load against a test PKI
// the openssl command line makes here (tests/support/make_test_pki.sh), each refusal located at
// its key with the reason OpenSSL gives, where Fast DDS would only say that it cannot create the
// participant.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/admission.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

class DdsSecurityConfig : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    pki_ = std::filesystem::path(testing::TempDir()) / ("dds_security_pki_" + std::to_string(::getpid()));
    const std::string command =
        std::string(build_paths::source_dir) + "/tests/support/make_test_pki.sh " + pki_.string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(pki_); }

  // The segment's security with `files` in place of the defaults (gateway-a's identity).
  ConfigResult load(const std::map<std::string, std::string>& files, const LoadOptions& options = {},
                    const std::string& gateway = "") {
    std::map<std::string, std::string> keys{
        {"identity_ca", "identity_ca.pem"},   {"certificate", "gateway-a_cert.pem"},
        {"private_key", "gateway-a_key.pem"}, {"permissions_ca", "permissions_ca.pem"},
        {"governance", "governance.p7s"},     {"permissions", "permissions.p7s"}};
    for (const auto& [k, v] : files) {
      if (v.empty()) {
        keys.erase(k);
      } else {
        keys[k] = v;
      }
    }
    std::string security;
    for (const auto& [k, v] : keys) security += (security.empty() ? "" : ", ") + k + ": " + v;
    const std::string text = gateway +
                             "segments:\n"
                             "  - name: lan\n"
                             "    type: dds\n"
                             "    domain: 4\n"
                             "    security: {" +
                             security +
                             "}\n"
                             "channels: []\n";
    security_line_ = "    security: {" + security + "}";
    return parse_config(text, (pki_ / "gateway.yaml").string(), options);
  }

  // The one error of `result`, which must be at security.KEY and say `fragment`.
  void expect_refused(const ConfigResult& result, const std::string& key, const std::string& fragment) {
    ASSERT_EQ(result.errors.size(), 1u) << (result.errors.empty() ? "" : result.errors.back().to_string());
    EXPECT_EQ(result.errors.front().path, "segments[0].security." + key);
    EXPECT_EQ(result.errors.front().line, 5);
    // All six keys stand on that line: the column tells which one (its value's, or the map's when missing).
    const auto at = security_line_.find(key + ": ");
    const int column = at == std::string::npos ? static_cast<int>(security_line_.find('{')) + 1
                                               : static_cast<int>(at + key.size() + 2) + 1;
    EXPECT_EQ(result.errors.front().column, column) << result.errors.front().to_string();
    EXPECT_NE(result.errors.front().message.find(fragment), std::string::npos) << result.errors.front().to_string();
  }

  static std::filesystem::path pki_;
  std::string security_line_;  // the YAML line of the last load()'s security map
};

std::filesystem::path DdsSecurityConfig::pki_;

TEST_F(DdsSecurityConfig, AValidIdentityAndSignedDocumentsLoad) {
  const ConfigResult result = load({});
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const auto& security = result.config.find_segment("lan")->dds.security;
  ASSERT_TRUE(security);
  EXPECT_EQ(security->subject, "/O=cosmic/CN=gateway-a");
  EXPECT_EQ(security->certificate, (pki_ / "gateway-a_cert.pem").string());
  EXPECT_EQ(security->governance, (pki_ / "governance.p7s").string());
  EXPECT_NE(security->content_hash, 0u);
}

TEST_F(DdsSecurityConfig, APrivateKeyOthersMayReadIsRefused) {
  expect_refused(load({{"private_key", "open_key.pem"}}), "private_key", "group or others may read or write it");
}

TEST_F(DdsSecurityConfig, AnExpiredCertificateIsRefused) {
  expect_refused(load({{"certificate", "expired.pem"}, {"private_key", "gateway-b_key.pem"}}), "certificate",
                 "certificate has expired");
}

TEST_F(DdsSecurityConfig, ACertificateOfAnotherCaIsRefused) {
  expect_refused(load({{"identity_ca", "rogue_ca.pem"}}), "certificate", "unable to get local issuer certificate");
}

TEST_F(DdsSecurityConfig, AKeyThatIsNotTheCertificatesIsRefused) {
  expect_refused(load({{"private_key", "gateway-b_key.pem"}}), "private_key", "is not the key of the certificate");
}

TEST_F(DdsSecurityConfig, UnsignedOrForeignSignedDocumentsAreRefused) {
  expect_refused(load({{"governance", "governance_unsigned.xml"}}), "governance", "is not an S/MIME signed document");
  expect_refused(load({{"permissions", "permissions_rogue.p7s"}}), "permissions",
                 "does not verify against the permissions CA");
}

TEST_F(DdsSecurityConfig, EveryFileIsNeededAndMissingOnesAreNamed) {
  expect_refused(load({{"permissions", ""}}), "permissions", "missing key 'permissions'");
  expect_refused(load({{"governance", "nowhere.p7s"}}), "governance", "No such file or directory");
}

// Material made here with the openssl command line, in the test PKI's directory; false when it failed.
bool in_pki(const std::filesystem::path& pki, const std::string& commands) {
  const std::string command = "cd " + pki.string() + " && (" + commands + ") >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

TEST_F(DdsSecurityConfig, ACertificateNotYetValidIsRefused) {
  ASSERT_TRUE(in_pki(pki_,
                     "openssl req -new -key gateway-a_key.pem -subj /O=cosmic/CN=gateway-a -out future.csr && "
                     "openssl ca -batch -config ca.cnf -extensions leaf -cert identity_ca.pem -keyfile "
                     "identity_ca_key.pem -startdate 20990101000000Z -enddate 21000101000000Z -in future.csr "
                     "-out future.pem -notext"));
  expect_refused(load({{"certificate", "future.pem"}}), "certificate", "certificate is not yet valid");
}

TEST_F(DdsSecurityConfig, AnEncryptedPrivateKeyIsRefused) {
  ASSERT_TRUE(in_pki(pki_,
                     "openssl pkey -in gateway-a_key.pem -aes256 -passout pass:secret -out encrypted_key.pem && "
                     "chmod 600 encrypted_key.pem"));
  expect_refused(load({{"private_key", "encrypted_key.pem"}}), "private_key", "holds no unencrypted PEM private key");
}

TEST_F(DdsSecurityConfig, AnEmptyCaFileIsRefusedAtItsKeyOnce) {
  ASSERT_TRUE(in_pki(pki_, ": > empty_ca.pem"));
  expect_refused(load({{"identity_ca", "empty_ca.pem"}}), "identity_ca", "holds no PEM certificate");
  expect_refused(load({{"permissions_ca", "empty_ca.pem"}}), "permissions_ca", "holds no PEM certificate");
}

TEST_F(DdsSecurityConfig, ARevokedCertificateIsRefusedWhenTheCaFileCarriesItsList) {
  // The identity CA file with a revocation list naming gateway-a's certificate, as Fast DDS reads it.
  ASSERT_TRUE(in_pki(pki_,
                     "openssl ca -config ca.cnf -cert identity_ca.pem -keyfile identity_ca_key.pem "
                     "-revoke gateway-a_cert.pem && "
                     "openssl ca -gencrl -crldays 30 -config ca.cnf -cert identity_ca.pem -keyfile identity_ca_key.pem "
                     "-out revoked.crl && cat identity_ca.pem revoked.crl > identity_ca_crl.pem"));
  expect_refused(load({{"identity_ca", "identity_ca_crl.pem"}}), "certificate", "certificate revoked");
  // gateway-b's certificate is not on the list: the same CA file accepts it.
  const ConfigResult b = load({{"identity_ca", "identity_ca_crl.pem"},
                               {"certificate", "gateway-b_cert.pem"},
                               {"private_key", "gateway-b_key.pem"}});
  EXPECT_TRUE(b.errors.empty()) << b.errors.front().to_string();
}

// `cosmicctl security permissions` loads the configuration before the documents it writes exist:
// their paths are resolved, nothing else is let off.
TEST_F(DdsSecurityConfig, PendingDocumentsNeedNotExistButEverythingElseIsChecked) {
  LoadOptions pending;
  pending.security_documents_pending = true;
  const std::map<std::string, std::string> absent{{"governance", "out/governance.p7s"},
                                                  {"permissions", "out/permissions.p7s"}};
  const ConfigResult result = load(absent, pending);
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const auto& security = result.config.find_segment("lan")->dds.security;
  ASSERT_TRUE(security);
  EXPECT_EQ(security->governance, (pki_ / "out/governance.p7s").string());
  EXPECT_EQ(security->permissions, (pki_ / "out/permissions.p7s").string());
  EXPECT_EQ(security->subject, "/O=cosmic/CN=gateway-a");
  expect_refused(load({{"governance", "out/governance.p7s"}}), "governance", "No such file or directory");
  auto open_key = absent;
  open_key["private_key"] = "open_key.pem";
  expect_refused(load(open_key, pending), "private_key", "group or others may read or write it");
  expect_refused(load({{"permissions", ""}}, pending), "permissions", "missing key 'permissions'");
}

// A component's `subject` (its certificate's, RFC 2253) names it in the permissions; only DDS
// Security authenticates participants by subject.
TEST(ComponentSubject, IsReadOnADdsSegmentAndRefusedElsewhere) {
  const std::string segments =
      "segments:\n"
      "  - {name: lan, type: dds, domain: 4}\n"
      "  - {name: viz, type: lcm}\n"
      "channels:\n"
      "  - {name: obstacle, subject: 0x10, class: nrt, publishers: [lan], subscribers: [viz]}\n"
      "components:\n";
  const ConfigResult ok = parse_config(segments +
                                           "  - {name: detector, segment: lan, publishes: [obstacle], subject: "
                                           "\"CN=detector,O=cosmic\"}\n"
                                           "  - {name: viewer, segment: viz, subscribes: [obstacle]}\n",
                                       "components.yaml");
  ASSERT_TRUE(ok.errors.empty()) << ok.errors.front().to_string();
  EXPECT_EQ(ok.config.components[0].subject, "CN=detector,O=cosmic");
  EXPECT_EQ(ok.config.components[1].subject, "");
  const ConfigResult on_lcm =
      parse_config(segments +
                       "  - {name: detector, segment: lan, publishes: [obstacle]}\n"
                       "  - {name: viewer, segment: viz, subscribes: [obstacle], subject: \"CN=viewer\"}\n",
                   "components.yaml");
  ASSERT_EQ(on_lcm.errors.size(), 1u);
  EXPECT_EQ(on_lcm.errors[0].path, "components[1].subject");
  EXPECT_EQ(on_lcm.errors[0].line, 8);
  EXPECT_NE(on_lcm.errors[0].message.find("lcm segment 'viz'"), std::string::npos) << on_lcm.errors[0].to_string();
  const ConfigResult not_a_name = parse_config(
      segments + "  - {name: detector, segment: lan, publishes: [obstacle], subject: detector}\n", "components.yaml");
  ASSERT_EQ(not_a_name.errors.size(), 1u);
  EXPECT_EQ(not_a_name.errors[0].path, "components[0].subject");
  EXPECT_NE(not_a_name.errors[0].message.find("is not a distinguished name"), std::string::npos);
}

// What DDS Security adds on a hop (docs/security.md): the transformations' bytes at most in the
// frame fit and the load, and the configured cost in the hop's latency.
TEST_F(DdsSecurityConfig, AdmissionCountsWhatSecurityAddsToEachSample) {
  const auto with = [&](const std::string& cost) {
    const std::string text =
        "segments:\n"
        "  - {name: lan, type: dds, domain: 4, realtime: true, latency_bound: 1ms}\n"
        "  - name: secure\n"
        "    type: dds\n"
        "    domain: 5\n"
        "    realtime: true\n"
        "    latency_bound: 1ms\n"
        "    security: {identity_ca: identity_ca.pem, certificate: gateway-a_cert.pem, private_key: "
        "gateway-a_key.pem,\n"
        "               permissions_ca: permissions_ca.pem, governance: governance.p7s, permissions: permissions.p7s" +
        cost +
        "}\n"
        "channels:\n"
        "  - {name: obstacle, subject: 0x10, class: hrt, period: 10ms, reaction_time: 4ms, payload: 64B,\n"
        "     publishers: [lan], subscribers: [secure]}\n";
    return parse_config(text, (pki_ / "gateway.yaml").string());
  };
  const ConfigResult plain = with("");
  ASSERT_TRUE(plain.errors.empty()) << plain.errors.front().to_string();
  EXPECT_FALSE(plain.config.find_segment("secure")->dds.security->cost);
  const Evaluation e = evaluate(plain.config.gateway, plain.config.segments, plain.config.channels, {});
  const ChannelReport& r = e.channels.front();
  const HopReport& secure = r.hops.back();
  ASSERT_EQ(secure.segment, "secure");
  ASSERT_TRUE(secure.security);
  EXPECT_EQ(secure.security->scheme, "DDS Security AES-GCM-GMAC");
  EXPECT_EQ(secure.security->bytes, 156u);
  EXPECT_FALSE(r.hops.front().security);
  EXPECT_EQ(secure.latency, std::chrono::milliseconds(1));
  // 1 ms + residence + 1 ms within 4 ms: bound. With 3 ms of cryptography on the secure hop: not.
  EXPECT_EQ(r.verdict, Verdict::bound);
  const ConfigResult costed = with(", cost: 3ms");
  ASSERT_TRUE(costed.errors.empty()) << costed.errors.front().to_string();
  const Evaluation c = evaluate(costed.config.gateway, costed.config.segments, costed.config.channels, {});
  EXPECT_EQ(c.channels.front().hops.back().latency, std::chrono::milliseconds(4));
  EXPECT_EQ(c.channels.front().verdict, Verdict::rejected);
  const ConfigResult bad = with(", cost: soon");
  ASSERT_EQ(bad.errors.size(), 1u);
  EXPECT_EQ(bad.errors.front().path, "segments[1].security.cost");
}

// gateway.federation.peers on a secure federation segment: each subject read in either form and
// normalised, with its participant keys; a malformed one refused where it stands.
TEST_F(DdsSecurityConfig, FederationPeersAreReadAsSubjectsOnASecureSegment) {
  const ConfigResult result = load(
      {}, {}, "gateway:\n  federation: {segment: lan, peers: ['CN=gateway-b,O=cosmic', /O=cosmic/CN=gateway-c]}\n");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const auto& peers = result.config.gateway.federation.peers;
  ASSERT_EQ(peers.size(), 2u);
  EXPECT_EQ(peers[0].subject, "/O=cosmic/CN=gateway-b");
  EXPECT_EQ(peers[1].subject, "/O=cosmic/CN=gateway-c");
  // O and CN may each be UTF8String or PrintableString in a certificate: four keys.
  EXPECT_EQ(peers[0].key_prefixes.size(), 4u);
  EXPECT_NE(peers[0].key_prefixes, peers[1].key_prefixes);

  const ConfigResult bad =
      load({}, {}, "gateway:\n  federation: {segment: lan, peers: [CN=gateway-b, 'CN=gateway-c,O']}\n");
  ASSERT_EQ(bad.errors.size(), 1u);
  EXPECT_EQ(bad.errors.front().path, "gateway.federation.peers[1]");
  EXPECT_EQ(bad.errors.front().line, 2);
  EXPECT_EQ(bad.errors.front().column, 52);
  EXPECT_NE(bad.errors.front().message.find("'CN=gateway-c,O' is not a certificate subject: 'O' has no '='"),
            std::string::npos)
      << bad.errors.front().to_string();
}

}  // namespace
}  // namespace cosmic

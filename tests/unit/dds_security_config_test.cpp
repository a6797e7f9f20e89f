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
  ConfigResult load(const std::map<std::string, std::string>& files, const std::string& gateway = "") {
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
    return parse_config(text, (pki_ / "gateway.yaml").string());
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

// gateway.federation.peers on a secure federation segment: each subject read in either form and
// normalised, with its participant keys; a malformed one refused where it stands.
TEST_F(DdsSecurityConfig, FederationPeersAreReadAsSubjectsOnASecureSegment) {
  const ConfigResult result =
      load({}, "gateway:\n  federation: {segment: lan, peers: ['CN=gateway-b,O=cosmic', /O=cosmic/CN=gateway-c]}\n");
  ASSERT_TRUE(result.errors.empty()) << result.errors.front().to_string();
  const auto& peers = result.config.gateway.federation.peers;
  ASSERT_EQ(peers.size(), 2u);
  EXPECT_EQ(peers[0].subject, "/O=cosmic/CN=gateway-b");
  EXPECT_EQ(peers[1].subject, "/O=cosmic/CN=gateway-c");
  // O and CN may each be UTF8String or PrintableString in a certificate: four keys.
  EXPECT_EQ(peers[0].key_prefixes.size(), 4u);
  EXPECT_NE(peers[0].key_prefixes, peers[1].key_prefixes);

  const ConfigResult bad =
      load({}, "gateway:\n  federation: {segment: lan, peers: [CN=gateway-b, 'CN=gateway-c,O']}\n");
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

// Signing DDS Security documents and reading what a grant needs from a certificate
// (cosmic/smime_sign.hpp), against a test PKI the openssl command line makes here
// (tests/support/make_test_pki.sh): the subject in RFC 2253 form and the validity as openssl
// prints them, a signed document that the loader's check (as Fast DDS verifies) and `openssl
// smime -verify` accept, and the refusals: another CA's key, a CA that may not sign, no key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cosmic/build_paths.hpp"
#include "cosmic/dds_security_files.hpp"
#include "cosmic/smime_sign.hpp"

namespace cosmic {
namespace {

class SmimeSign : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    pki_ = std::filesystem::path(testing::TempDir()) / ("smime_sign_pki_" + std::to_string(::getpid()));
    const std::string command =
        std::string(build_paths::source_dir) + "/tests/support/make_test_pki.sh " + pki_.string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(pki_); }

  static std::string file(const std::string& name) {
    std::ifstream in(pki_ / name);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

  // What a shell command prints on its standard output.
  static std::string output_of(const std::string& command) {
    std::string out;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
      char buffer[512];
      while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) out += buffer;
      ::pclose(pipe);
    }
    while (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  }

  static std::filesystem::path pki_;
};

std::filesystem::path SmimeSign::pki_;

const char* const kSignedXml =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<dds>\n  <permissions>R&amp;D</permissions>\n</dds>\n";

TEST_F(SmimeSign, ACertificatesSubjectIsInRfc2253FormAndItsValidityInUtc) {
  const auto facts = certificate_facts(file("gateway-a_cert.pem"));
  ASSERT_TRUE(facts) << facts.error().text;
  EXPECT_EQ(facts.value().subject, "CN=gateway-a,O=cosmic");
  // As openssl prints them (make_test_pki.sh issues certificates for 30 days from now).
  const std::string certificate = (pki_ / "gateway-a_cert.pem").string();
  const std::string to_grant_time = " | cut -d= -f2 | xargs -I{} date -u -d {} +%Y-%m-%dT%H:%M:%S";
  EXPECT_EQ(facts.value().not_before, output_of("openssl x509 -noout -startdate -in " + certificate + to_grant_time));
  EXPECT_EQ(facts.value().not_after, output_of("openssl x509 -noout -enddate -in " + certificate + to_grant_time));
  EXPECT_FALSE(certificate_facts("no certificate here"));
}

TEST_F(SmimeSign, ASignedDocumentVerifiesAsFastDdsAndOpensslCheckIt) {
  const auto signed_text = smime_sign_text(kSignedXml, file("permissions_ca.pem"), file("permissions_ca_key.pem"));
  ASSERT_TRUE(signed_text) << signed_text.error().text;
  EXPECT_NE(signed_text.value().find("Content-Type: multipart/signed"), std::string::npos) << signed_text.value();
  EXPECT_TRUE(check_signed_document(file("permissions_ca.pem"), signed_text.value()));
  EXPECT_FALSE(check_signed_document(file("rogue_ca.pem"), signed_text.value()));
  const auto signed_path = pki_ / "signed.p7s";
  std::ofstream(signed_path) << signed_text.value();
  // -text: the content comes back without its MIME header, the document in the canonical form
  // S/MIME signs (CRLF line ends, as in what `openssl smime -sign -text` writes itself).
  std::string verified = output_of("openssl smime -verify -text -in " + signed_path.string() + " -CAfile " +
                                   (pki_ / "permissions_ca.pem").string() + " 2>/dev/null");
  std::erase(verified, '\r');
  EXPECT_EQ(verified + "\n", kSignedXml);
}

TEST_F(SmimeSign, AKeyThatIsNotTheCasOrACaThatMayNotSignIsRefused) {
  const auto wrong_key = smime_sign_text(kSignedXml, file("permissions_ca.pem"), file("rogue_ca_key.pem"));
  ASSERT_FALSE(wrong_key);
  EXPECT_EQ(wrong_key.error().text, "the CA key is not the key of the CA certificate");
  // The identity CA's keyUsage is keyCertSign and cRLSign only.
  const auto no_signing = smime_sign_text(kSignedXml, file("identity_ca.pem"), file("identity_ca_key.pem"));
  ASSERT_FALSE(no_signing);
  EXPECT_NE(no_signing.error().text.find("leaves out digitalSignature"), std::string::npos) << no_signing.error().text;
  const auto no_key = smime_sign_text(kSignedXml, file("permissions_ca.pem"), file("permissions_ca.pem"));
  ASSERT_FALSE(no_key);
  EXPECT_NE(no_key.error().text.find("holds no unencrypted PEM private key"), std::string::npos) << no_key.error().text;
}

}  // namespace
}  // namespace cosmic

// The throw-away PKI of `cosmicctl calibrate` (cosmic/ephemeral_pki.hpp): its identities chain to
// its CA and are valid now, as the loader's checks (which follow Fast DDS's PKI-DH) and `openssl
// verify` see them; their subjects read as grants name them; the CA signs documents that verify
// against it; every call makes new keys; an empty name is refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cosmic/dds_security_files.hpp"
#include "cosmic/ephemeral_pki.hpp"
#include "cosmic/smime_sign.hpp"

namespace cosmic {
namespace {

const std::vector<std::string> kNames{"calibrate-writer", "calibrate-reader"};

TEST(EphemeralPki, IdentitiesChainToTheCaAndAreValidNowAsTheLoaderChecksThem) {
  const auto pki = make_ephemeral_pki(kNames, std::chrono::hours(1));
  ASSERT_TRUE(pki) << pki.error().text;
  const EphemeralPki& p = pki.value();
  EXPECT_TRUE(check_ca_certificate(p.ca_certificate_pem));
  ASSERT_EQ(p.identities.size(), 2u);
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    const EphemeralIdentity& identity = p.identities[i];
    EXPECT_EQ(identity.name, kNames[i]);
    EXPECT_EQ(identity.subject, "CN=" + kNames[i] + ",O=cosmic");
    const auto subject = check_identity_certificate(p.ca_certificate_pem, identity.certificate_pem);
    ASSERT_TRUE(subject) << subject.error().text;
    EXPECT_EQ(subject.value(), "/O=cosmic/CN=" + kNames[i]);
    EXPECT_TRUE(check_private_key(identity.private_key_pem, identity.certificate_pem));
  }
  // Keys are not interchangeable: the writer's key is not the reader's certificate's.
  EXPECT_FALSE(check_private_key(p.identities[0].private_key_pem, p.identities[1].certificate_pem));
  const auto facts = certificate_facts(p.identities[0].certificate_pem);
  ASSERT_TRUE(facts);
  EXPECT_EQ(facts.value().not_before, p.not_before);
  EXPECT_EQ(facts.value().not_after, p.not_after);
  EXPECT_LT(p.not_before, p.not_after);
}

TEST(EphemeralPki, TheCaSignsDocumentsThatVerifyAgainstIt) {
  const auto pki = make_ephemeral_pki(kNames, std::chrono::hours(1));
  ASSERT_TRUE(pki) << pki.error().text;
  const auto signed_text =
      smime_sign_text("<dds><governance/></dds>\n", pki.value().ca_certificate_pem, pki.value().ca_private_key_pem);
  ASSERT_TRUE(signed_text) << signed_text.error().text;
  EXPECT_TRUE(check_signed_document(pki.value().ca_certificate_pem, signed_text.value()));
  const auto other = make_ephemeral_pki(kNames, std::chrono::hours(1));
  ASSERT_TRUE(other);
  EXPECT_FALSE(check_signed_document(other.value().ca_certificate_pem, signed_text.value()))
      << "each call makes a CA of its own";
}

TEST(EphemeralPki, OpensslVerifiesTheIdentitiesAgainstTheCa) {
  const auto pki = make_ephemeral_pki(kNames, std::chrono::hours(1));
  ASSERT_TRUE(pki) << pki.error().text;
  const auto dir = std::filesystem::path(testing::TempDir()) / ("ephemeral_pki_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "ca.pem") << pki.value().ca_certificate_pem;
  std::ofstream(dir / "writer.pem") << pki.value().identities[0].certificate_pem;
  const std::string verify = "openssl verify -x509_strict -purpose any -CAfile " + (dir / "ca.pem").string() + " " +
                             (dir / "writer.pem").string() + " >/dev/null 2>&1";
  EXPECT_EQ(std::system(verify.c_str()), 0) << verify;
  const std::string self = "openssl verify -CAfile " + (dir / "writer.pem").string() + " " +
                           (dir / "writer.pem").string() + " >/dev/null 2>&1";
  EXPECT_NE(std::system(self.c_str()), 0) << "an identity is no CA";
  std::filesystem::remove_all(dir);
}

TEST(EphemeralPki, AnEmptyNameIsRefused) {
  const std::vector<std::string> names{"calibrate-writer", ""};
  const auto pki = make_ephemeral_pki(names, std::chrono::hours(1));
  ASSERT_FALSE(pki);
  EXPECT_EQ(pki.error().text, "an identity needs a name");
}

}  // namespace
}  // namespace cosmic

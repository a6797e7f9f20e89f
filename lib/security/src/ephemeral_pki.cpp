// A throw-away CA and identities (cosmic/ephemeral_pki.hpp).
#include "cosmic/ephemeral_pki.hpp"

#include <openssl/pem.h>
#include <openssl/x509v3.h>

#include "cosmic/smime_sign.hpp"
#include "openssl_handles.hpp"

namespace cosmic {
namespace {

using security_detail::Bio;
using security_detail::Certificate;
using security_detail::PrivateKey;

struct ExtensionFree {
  void operator()(X509_EXTENSION* e) const noexcept { X509_EXTENSION_free(e); }
};

Error failed(const std::string& what) { return Error{what + ": " + security_detail::openssl_reason()}; }

Result<PrivateKey> new_key() {
  PrivateKey key(EVP_EC_gen("P-256"));
  if (!key) return failed("cannot generate an ECDSA P-256 key");
  return key;
}

// The name "O=cosmic,CN=<common_name>" set as `certificate`'s subject.
bool set_subject(X509* certificate, const std::string& common_name) {
  X509_NAME* name = X509_get_subject_name(certificate);
  const auto* organization = reinterpret_cast<const unsigned char*>("cosmic");
  const auto* cn = reinterpret_cast<const unsigned char*>(common_name.c_str());
  return X509_NAME_add_entry_by_txt(name, "O", MBSTRING_UTF8, organization, -1, -1, 0) == 1 &&
         X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, cn, -1, -1, 0) == 1;
}

bool add_extension(X509* certificate, X509* issuer, int nid, const char* value) {
  X509V3_CTX context;
  X509V3_set_ctx_nodb(&context);
  X509V3_set_ctx(&context, issuer, certificate, nullptr, nullptr, 0);
  const std::unique_ptr<X509_EXTENSION, ExtensionFree> extension(X509V3_EXT_conf_nid(nullptr, &context, nid, value));
  return extension && X509_add_ext(certificate, extension.get(), -1) == 1;
}

// A certificate of `common_name` for `key`, signed by `issuer` with `issuer_key` (itself when null).
Result<Certificate> new_certificate(const std::string& common_name, EVP_PKEY* key, X509* issuer, EVP_PKEY* issuer_key,
                                    long serial, std::chrono::seconds validity) {
  Certificate certificate(X509_new());
  if (!certificate) return failed("cannot make a certificate");
  X509* c = certificate.get();
  const bool authority = issuer == nullptr;
  const bool made = X509_set_version(c, X509_VERSION_3) == 1 &&
                    ASN1_INTEGER_set(X509_get_serialNumber(c), serial) == 1 &&
                    X509_gmtime_adj(X509_getm_notBefore(c), -60) != nullptr &&
                    X509_gmtime_adj(X509_getm_notAfter(c), static_cast<long>(validity.count())) != nullptr &&
                    X509_set_pubkey(c, key) == 1 && set_subject(c, common_name) &&
                    X509_set_issuer_name(c, X509_get_subject_name(authority ? c : issuer)) == 1 &&
                    add_extension(c, authority ? c : issuer, NID_basic_constraints,
                                  authority ? "critical,CA:TRUE" : "critical,CA:FALSE") &&
                    add_extension(c, authority ? c : issuer, NID_key_usage,
                                  authority ? "critical,keyCertSign,cRLSign,digitalSignature"
                                            : "critical,digitalSignature,keyAgreement") &&
                    // Key identifiers: strict verification (the loader's, X509_STRICT) wants both; the subject's first.
                    add_extension(c, authority ? c : issuer, NID_subject_key_identifier, "hash") &&
                    add_extension(c, authority ? c : issuer, NID_authority_key_identifier, "keyid:always") &&
                    X509_sign(c, authority ? key : issuer_key, EVP_sha256()) > 0;
  if (!made) return failed("cannot make the certificate of " + common_name);
  return certificate;
}

Result<std::string> pem_of(X509* certificate) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_X509(out.get(), certificate) != 1) return failed("cannot write a certificate");
  return security_detail::text_of(out.get());
}

Result<std::string> pem_of(EVP_PKEY* key) {
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || PEM_write_bio_PrivateKey(out.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1)
    return failed("cannot write a private key");
  return security_detail::text_of(out.get());
}

// `identity` made and signed by the CA, its subject and validity read back as grants write them.
Result<EphemeralIdentity> new_identity(const std::string& name, X509* ca, EVP_PKEY* ca_key, long serial,
                                       std::chrono::seconds validity) {
  auto key = new_key();
  if (!key) return std::move(key).error();
  auto certificate = new_certificate(name, key.value().get(), ca, ca_key, serial, validity);
  if (!certificate) return std::move(certificate).error();
  auto certificate_pem = pem_of(certificate.value().get());
  if (!certificate_pem) return std::move(certificate_pem).error();
  auto key_pem = pem_of(key.value().get());
  if (!key_pem) return std::move(key_pem).error();
  auto facts = certificate_facts(certificate_pem.value());
  if (!facts) return std::move(facts).error();
  return EphemeralIdentity{name, facts.value().subject, std::move(certificate_pem).value(), std::move(key_pem).value()};
}

}  // namespace

Result<EphemeralPki> make_ephemeral_pki(std::span<const std::string> names, std::chrono::seconds validity) {
  for (const auto& name : names)
    if (name.empty()) return Error{"an identity needs a name"};
  auto ca_key = new_key();
  if (!ca_key) return std::move(ca_key).error();
  auto ca = new_certificate("cosmic ephemeral CA", ca_key.value().get(), nullptr, nullptr, 1, validity);
  if (!ca) return std::move(ca).error();
  EphemeralPki pki;
  auto ca_pem = pem_of(ca.value().get());
  if (!ca_pem) return std::move(ca_pem).error();
  auto ca_key_pem = pem_of(ca_key.value().get());
  if (!ca_key_pem) return std::move(ca_key_pem).error();
  pki.ca_certificate_pem = std::move(ca_pem).value();
  pki.ca_private_key_pem = std::move(ca_key_pem).value();
  long serial = 2;
  for (const auto& name : names) {
    auto identity = new_identity(name, ca.value().get(), ca_key.value().get(), serial++, validity);
    if (!identity) return std::move(identity).error();
    pki.identities.push_back(std::move(identity).value());
  }
  auto facts = certificate_facts(pki.ca_certificate_pem);
  if (!facts) return std::move(facts).error();
  pki.not_before = facts.value().not_before;
  pki.not_after = facts.value().not_after;
  return pki;
}

}  // namespace cosmic

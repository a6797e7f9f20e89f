// Certificates' facts and S/MIME signing (cosmic/smime_sign.hpp).
#include "cosmic/smime_sign.hpp"

#include <openssl/x509v3.h>

#include <ctime>

#include "openssl_handles.hpp"

namespace cosmic {
using security_detail::Bio;

namespace {

// An ASN.1 time as a grant's validity writes it (xs:dateTime without a zone, UTC).
Result<std::string> grant_time(const ASN1_TIME* time) {
  std::tm parts{};
  if (time == nullptr || ASN1_TIME_to_tm(time, &parts) != 1) return Error{"a validity date does not read"};
  char text[32];
  if (std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &parts) == 0)
    return Error{"a validity date is out of range"};
  return std::string(text);
}

}  // namespace

Result<CertificateFacts> certificate_facts(const std::string& certificate_pem) {
  const auto certificates = security_detail::certificates_of(certificate_pem);
  if (certificates.empty()) return Error{"holds no PEM certificate"};
  X509* certificate = certificates.front().get();
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || X509_NAME_print_ex(out.get(), X509_get_subject_name(certificate), 0, XN_FLAG_RFC2253) < 0)
    return Error{"cannot print its subject: " + security_detail::openssl_reason()};
  CertificateFacts facts;
  facts.subject = security_detail::text_of(out.get());
  if (facts.subject.empty()) return Error{"its subject is empty: a permissions grant could not name it"};
  auto not_before = grant_time(X509_get0_notBefore(certificate));
  if (!not_before) return std::move(not_before).error();
  auto not_after = grant_time(X509_get0_notAfter(certificate));
  if (!not_after) return std::move(not_after).error();
  facts.not_before = std::move(not_before).value();
  facts.not_after = std::move(not_after).value();
  return facts;
}

Result<std::string> smime_sign_text(const std::string& text, const std::string& ca_certificate_pem,
                                    const std::string& ca_key_pem) {
  const auto certificates = security_detail::certificates_of(ca_certificate_pem);
  if (certificates.empty()) return Error{"the CA certificate file holds no PEM certificate"};
  X509* certificate = certificates.front().get();
  const security_detail::PrivateKey key = security_detail::private_key_of(ca_key_pem);
  if (!key)
    return Error{"the CA key file holds no unencrypted PEM private key (" + security_detail::openssl_reason() + ")"};
  if (X509_check_private_key(certificate, key.get()) != 1) {
    ERR_clear_error();
    return Error{"the CA key is not the key of the CA certificate"};
  }
  // X509_get_key_usage: every usage when the certificate has no keyUsage extension.
  if ((X509_get_key_usage(certificate) & KU_DIGITAL_SIGNATURE) == 0)
    return Error{"the CA certificate's keyUsage leaves out digitalSignature: its signatures would be refused"};
  constexpr int kFlags = PKCS7_TEXT | PKCS7_DETACHED;
  Bio content = security_detail::memory_of(text);
  const security_detail::Pkcs7 signature(PKCS7_sign(certificate, key.get(), nullptr, content.get(), kFlags));
  if (!signature) return Error{"cannot sign: " + security_detail::openssl_reason()};
  // Detached: the message carries the text again, as it was signed (PKCS7_TEXT adds the same header).
  Bio again = security_detail::memory_of(text);
  Bio out(BIO_new(BIO_s_mem()));
  if (!out || SMIME_write_PKCS7(out.get(), signature.get(), again.get(), kFlags) != 1)
    return Error{"cannot write the S/MIME message: " + security_detail::openssl_reason()};
  return security_detail::text_of(out.get());
}

}  // namespace cosmic

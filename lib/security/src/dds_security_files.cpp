#include "cosmic/dds_security_files.hpp"

#include <openssl/pem.h>

#include "openssl_handles.hpp"

namespace cosmic {
using security_detail::Bio;
using security_detail::Certificate;
using security_detail::certificates_of;
using security_detail::memory_of;
using security_detail::openssl_reason;
using security_detail::Pkcs7;
using security_detail::private_key_of;
using security_detail::PrivateKey;
using security_detail::StoreContextFree;
using security_detail::StoreFree;

namespace {

// The certificate revocation lists a CA file carries besides its certificates (Fast DDS reads them
// from the identity CA file and then checks revocation).
std::size_t add_revocation_lists(X509_STORE* store, const std::string& pem) {
  std::size_t count = 0;
  Bio bio = memory_of(pem);
  while (bio) {
    X509_CRL* list = PEM_read_bio_X509_CRL(bio.get(), nullptr, nullptr, nullptr);
    if (list == nullptr) break;
    X509_STORE_add_crl(store, list);
    X509_CRL_free(list);
    ++count;
  }
  ERR_clear_error();
  return count;
}

std::unique_ptr<X509_STORE, StoreFree> store_of(const std::vector<Certificate>& authorities) {
  std::unique_ptr<X509_STORE, StoreFree> store(X509_STORE_new());
  if (!store) return store;
  for (const Certificate& c : authorities) X509_STORE_add_cert(store.get(), c.get());
  return store;
}

std::string one_line_subject(X509* certificate) {
  char buffer[512];
  X509_NAME_oneline(X509_get_subject_name(certificate), buffer, sizeof buffer);
  return buffer;
}

}  // namespace

Result<void> check_ca_certificate(const std::string& ca_pem) {
  if (certificates_of(ca_pem).empty()) return Error{"holds no PEM certificate"};
  return {};
}

Result<std::string> check_identity_certificate(const std::string& ca_pem, const std::string& certificate_pem) {
  const auto authorities = certificates_of(ca_pem);
  if (authorities.empty()) return Error{"the identity CA file holds no PEM certificate"};
  auto certificates = certificates_of(certificate_pem);
  if (certificates.empty()) return Error{"holds no PEM certificate"};
  X509* certificate = certificates.front().get();
  const auto store = store_of(authorities);
  std::unique_ptr<X509_STORE_CTX, StoreContextFree> context(X509_STORE_CTX_new());
  if (!store || !context || X509_STORE_CTX_init(context.get(), store.get(), certificate, nullptr) != 1)
    return Error{"cannot check it: " + openssl_reason()};
  // What Fast DDS's PKI-DH asks of the chain: strict X.509, the CA's own signature, its policies,
  // and revocation when the CA file carries lists; a certificate it would refuse is refused here.
  const bool revocation = add_revocation_lists(store.get(), ca_pem) > 0;
  X509_STORE_CTX_set_flags(context.get(), (revocation ? X509_V_FLAG_CRL_CHECK : 0) | X509_V_FLAG_X509_STRICT |
                                              X509_V_FLAG_CHECK_SS_SIGNATURE | X509_V_FLAG_POLICY_CHECK);
  if (X509_verify_cert(context.get()) != 1) {
    const int error = X509_STORE_CTX_get_error(context.get());
    ERR_clear_error();
    return Error{std::string(X509_verify_cert_error_string(error)) + " (" + one_line_subject(certificate) +
                 ", checked against the identity CA)"};
  }
  return one_line_subject(certificate);
}

Result<void> check_private_key(const std::string& key_pem, const std::string& certificate_pem) {
  const PrivateKey key = private_key_of(key_pem);
  if (!key) return Error{"holds no unencrypted PEM private key (" + openssl_reason() + ")"};
  auto certificates = certificates_of(certificate_pem);
  if (certificates.empty()) return {};  // the certificate's own error is reported at its key
  if (X509_check_private_key(certificates.front().get(), key.get()) != 1) {
    ERR_clear_error();
    return Error{"is not the key of the certificate (" + one_line_subject(certificates.front().get()) + ")"};
  }
  return {};
}

Result<void> check_signed_document(const std::string& ca_pem, const std::string& document) {
  const auto authorities = certificates_of(ca_pem);
  if (authorities.empty()) return Error{"the permissions CA file holds no PEM certificate"};
  Bio bio = memory_of(document);
  BIO* content = nullptr;
  Pkcs7 signed_data(SMIME_read_PKCS7(bio.get(), &content));
  const Bio content_owner(content);
  if (!signed_data) {
    return Error{"is not an S/MIME signed document (" + openssl_reason() +
                 "); sign it: openssl smime -sign -text -in FILE.xml -out FILE.p7s -signer CA.pem -inkey CA_KEY.pem"};
  }
  const auto store = store_of(authorities);
  Bio out(BIO_new(BIO_s_mem()));
  // As Fast DDS checks it: the content is text (PKCS7_TEXT strips the MIME header it carries).
  if (!store || PKCS7_verify(signed_data.get(), nullptr, store.get(), content, out.get(), PKCS7_TEXT) != 1)
    return Error{"its signature does not verify against the permissions CA (" + openssl_reason() + ")"};
  return {};
}

}  // namespace cosmic

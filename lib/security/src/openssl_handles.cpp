// OpenSSL helpers of the security library (openssl_handles.hpp).
#include "openssl_handles.hpp"

#include <openssl/pem.h>

namespace cosmic::security_detail {

std::string openssl_reason() {
  const unsigned long code = ERR_peek_last_error();
  ERR_clear_error();
  if (code == 0) return "unknown reason";
  const char* reason = ERR_reason_error_string(code);
  return reason != nullptr ? reason : "unknown reason";
}

Bio memory_of(const std::string& text) { return Bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size()))); }

std::string text_of(BIO* memory) {
  char* data = nullptr;
  const long size = BIO_get_mem_data(memory, &data);
  return size > 0 && data != nullptr ? std::string(data, static_cast<std::size_t>(size)) : std::string();
}

std::vector<Certificate> certificates_of(const std::string& pem) {
  std::vector<Certificate> out;
  Bio bio = memory_of(pem);
  while (bio) {
    X509* certificate = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr);
    if (certificate == nullptr) break;
    out.emplace_back(certificate);
  }
  ERR_clear_error();  // the end of the text reads as an error
  return out;
}

PrivateKey private_key_of(const std::string& pem) {
  Bio bio = memory_of(pem);
  // No password callback: an encrypted key fails here, as Fast DDS's PKI-DH would fail without one.
  char no_password[] = "";
  return PrivateKey(PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, no_password));
}

}  // namespace cosmic::security_detail

// OpenSSL objects owned by std::unique_ptr, and the reason of OpenSSL's last failure: shared by
// the DDS Security units of cosmic_security (checking the files, reading certificates, signing).
// Internal to the security library. Any thread.
#pragma once

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pkcs7.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>

#include <memory>
#include <string>
#include <vector>

namespace cosmic::security_detail {

struct BioFree {
  void operator()(BIO* b) const noexcept { BIO_free(b); }
};
struct X509Free {
  void operator()(X509* x) const noexcept { X509_free(x); }
};
struct StoreFree {
  void operator()(X509_STORE* s) const noexcept { X509_STORE_free(s); }
};
struct StoreContextFree {
  void operator()(X509_STORE_CTX* c) const noexcept { X509_STORE_CTX_free(c); }
};
struct KeyFree {
  void operator()(EVP_PKEY* k) const noexcept { EVP_PKEY_free(k); }
};
struct Pkcs7Free {
  void operator()(PKCS7* p) const noexcept { PKCS7_free(p); }
};
using Bio = std::unique_ptr<BIO, BioFree>;
using Certificate = std::unique_ptr<X509, X509Free>;
using PrivateKey = std::unique_ptr<EVP_PKEY, KeyFree>;
using Pkcs7 = std::unique_ptr<PKCS7, Pkcs7Free>;

// OpenSSL's reason for the last failure, and the queue emptied.
std::string openssl_reason();

// A read-only memory BIO over `text` (which must outlive it).
Bio memory_of(const std::string& text);

// The bytes written to a memory BIO.
std::string text_of(BIO* memory);

// Every PEM certificate in `pem`, in order.
std::vector<Certificate> certificates_of(const std::string& pem);

// The unencrypted PEM private key in `pem`, or null (openssl_reason() says why).
PrivateKey private_key_of(const std::string& pem);

}  // namespace cosmic::security_detail

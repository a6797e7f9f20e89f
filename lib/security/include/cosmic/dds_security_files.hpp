// The files of DDS Security (issue 36, item 1; DDS Security 1.1, the builtin PKI-DH and
// Access-Permissions plugins) checked before a participant is made with them, so that a wrong file
// is a located configuration error rather than Fast DDS's bare "Cannot create participant due to
// initialization error": the identity certificate chains to the identity CA and is valid now, the
// private key is the certificate's and not encrypted, and the governance and permissions documents
// are S/MIME signed (clear text, as `openssl smime -sign -text` writes them) by the permissions CA.
// The texts come from the caller (the configuration loader reads the files).
//
// Pure: no I/O; OpenSSL's libcrypto. Any thread.
#pragma once

#include <string>

#include "cosmic/result.hpp"

namespace cosmic {

// `certificate_pem` is a certificate issued by `ca_pem` (PEM, one or more certificates) and valid
// now; its subject in OpenSSL's one-line form ("/O=cosmic/CN=gateway-a") is returned.
Result<std::string> check_identity_certificate(const std::string& ca_pem, const std::string& certificate_pem);

// `key_pem` is an unencrypted private key (PEM) that belongs to `certificate_pem`.
Result<void> check_private_key(const std::string& key_pem, const std::string& certificate_pem);

// `ca_pem` holds at least one certificate (PEM).
Result<void> check_ca_certificate(const std::string& ca_pem);

// `document` is an S/MIME message signed by a certificate `ca_pem` issued (or is), with its
// content as text (the governance or permissions XML).
Result<void> check_signed_document(const std::string& ca_pem, const std::string& document);

}  // namespace cosmic

// Signing the DDS Security governance and permissions documents (issue 36, item 1;
// `cosmicctl security permissions --sign-with`) as the specification wants them (DDS Security 1.1,
// 9.4.1.3) and Fast DDS reads them: an S/MIME message, multipart/signed, with the XML as clear text
// (`openssl smime -sign -text`: the signed content is the text with a `Content-Type: text/plain`
// header), signed by the permissions CA and carrying its certificate. And what a grant needs from
// a participant's certificate: its subject as permissions documents write it, and its validity.
//
// Pure: no I/O (the caller reads the files); OpenSSL's libcrypto. Any thread.
#pragma once

#include <string>

#include "cosmic/result.hpp"

namespace cosmic {

struct CertificateFacts {
  std::string subject;     // RFC 2253, most specific first: "CN=gateway-a,O=cosmic"
  std::string not_before;  // UTC, as a grant's validity writes it: "2024-01-31T12:00:00"
  std::string not_after;
};

// The subject and validity of the first certificate in `certificate_pem`.
Result<CertificateFacts> certificate_facts(const std::string& certificate_pem);

// `text` signed by the CA whose certificate is `ca_certificate_pem` and private key `ca_key_pem`
// (unencrypted PEM): the S/MIME message as `openssl smime -sign -text` writes it. Refused, with
// the reason, when the key is not the certificate's, or the certificate's key usage leaves out
// digital signatures (a verifier would refuse the signature).
Result<std::string> smime_sign_text(const std::string& text, const std::string& ca_certificate_pem,
                                    const std::string& ca_key_pem);

}  // namespace cosmic

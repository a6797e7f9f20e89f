// A throw-away DDS Security PKI made in memory (issue 36, item 5; `cosmicctl calibrate`): one CA
// (ECDSA P-256) that serves as identity CA and permissions CA, and one identity per name it is
// asked for, "O=cosmic,CN=NAME", signed by it. Calibration gives two participants of its own these
// identities, so timing the cryptography never needs the operator's keys nor joins the operator's
// domain with them. Never for production identities: the CA's key lives only in the returned value.
//
// Pure: no I/O (the caller writes the PEM texts where Fast DDS reads them); OpenSSL's libcrypto.
// Any thread.
#pragma once

#include <chrono>
#include <span>
#include <string>
#include <vector>

#include "cosmic/result.hpp"

namespace cosmic {

struct EphemeralIdentity {
  std::string name;             // the CN
  std::string subject;          // RFC 2253, as grants name it: "CN=NAME,O=cosmic"
  std::string certificate_pem;  // signed by the CA
  std::string private_key_pem;  // unencrypted PKCS#8
};

struct EphemeralPki {
  std::string ca_certificate_pem;  // self-signed; keyCertSign and digitalSignature (it signs documents)
  std::string ca_private_key_pem;
  std::vector<EphemeralIdentity> identities;  // in the order of the names asked for
  std::string not_before;                     // every certificate's validity, as grants write it (UTC)
  std::string not_after;
};

// A CA and one identity per name, valid from a minute ago for `validity`. Fails only when OpenSSL
// does (the reason is OpenSSL's), or a name is empty.
Result<EphemeralPki> make_ephemeral_pki(std::span<const std::string> names, std::chrono::seconds validity);

}  // namespace cosmic

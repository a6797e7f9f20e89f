// A certificate's subject name as a configuration writes it (gateway.federation.peers,
// docs/federation.md), and the DDS participant keys DDS Security's PKI-DH gives its holder.
//
// Under the builtin PKI-DH plugin a participant's GUID prefix is not free: its first bit is 1 and
// its next 47 bits are the first 47 bits of SHA-256 over the DER encoding of its identity
// certificate's subject (DDS Security 1.1, 9.3.3; Fast DDS's PKIDH adjust_participant_key, and the
// handshake refuses a peer whose GUID does not follow from its certificate). So the first 6 bytes of
// an authenticated participant's GUID prefix tell which subject it authenticated with; the subject
// text the participant announces (its identity token's dds.cert.sn) is only its own claim.
//
// A subject is accepted as OpenSSL prints it in one line (`/O=cosmic/CN=gateway-b`, most general
// attribute first) or in RFC 2253 form (`CN=gateway-b,O=cosmic`, most specific first), with
// backslash escapes and `+` joining the attributes of one multi-valued RDN. Attribute names are
// OpenSSL's short or long names or dotted OIDs. The DER encoding of one text is not unique (an
// attribute may be a UTF8String or a PrintableString in a certificate): every encoding a
// certificate authority plausibly writes is hashed, so each subject has a few possible keys.
//
// Pure: no I/O; OpenSSL's libcrypto. Any thread.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/result.hpp"

namespace cosmic {

// The first 6 bytes of a participant's GUID prefix under PKI-DH: the bits that follow from its subject.
using SubjectKeyPrefix = std::array<std::uint8_t, 6>;

struct CertificateSubject {
  std::string text;                        // OpenSSL's one-line form: "/O=cosmic/CN=gateway-b"
  std::vector<SubjectKeyPrefix> prefixes;  // one per plausible DER encoding, without repeats
};

// The subject `text` (either form); an error saying what is wrong with it otherwise.
Result<CertificateSubject> parse_certificate_subject(std::string_view text);

// The PKI-DH key prefix of the subject whose DER encoding (an X.509 Name) is `der_name`.
SubjectKeyPrefix subject_key_prefix(std::span<const std::uint8_t> der_name);

// Whether a participant whose GUID prefix starts with `guid_prefix` (at least 6 bytes) holds
// `subject` (when it authenticated: the handshake proves it holds the certificate behind its GUID).
bool holds_subject(const CertificateSubject& subject, std::span<const std::uint8_t> guid_prefix);

}  // namespace cosmic

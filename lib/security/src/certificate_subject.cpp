#include "cosmic/certificate_subject.hpp"

#include <openssl/asn1.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/objects.h>
#include <openssl/x509.h>

#include <algorithm>
#include <memory>

namespace cosmic {
namespace {

// Attributes of one subject: enough for any real certificate; the limit keeps the encodings few.
constexpr std::size_t kMaxAttributes = 16;
// Every combination of plausible string types is hashed up to this many; beyond it, the types a
// certificate authority writes uniformly (all default, all UTF8String, all PrintableString).
constexpr std::size_t kMaxEncodings = 256;

struct Attribute {
  std::string type;
  std::string value;
  bool joins_previous = false;  // `+`: part of the previous attribute's RDN
};

struct NameFree {
  void operator()(X509_NAME* n) const noexcept { X509_NAME_free(n); }
};
struct EntryFree {
  void operator()(X509_NAME_ENTRY* e) const noexcept { X509_NAME_ENTRY_free(e); }
};
struct ObjectFree {
  void operator()(ASN1_OBJECT* o) const noexcept { ASN1_OBJECT_free(o); }
};
using Name = std::unique_ptr<X509_NAME, NameFree>;
using Entry = std::unique_ptr<X509_NAME_ENTRY, EntryFree>;
using Object = std::unique_ptr<ASN1_OBJECT, ObjectFree>;

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(' ');
  if (first == std::string_view::npos) return {};
  return std::string(s.substr(first, s.find_last_not_of(' ') - first + 1));
}

// Splits `text` into attributes: `separator` ends an RDN, `+` (RFC 2253 only: OpenSSL's one-line
// form has no multi-valued RDNs and writes a `+` as it is) an attribute within it; a backslash
// takes the next character as it is, or two hexadecimal digits as a byte. Spaces around a type and
// unescaped spaces around a value are not part of them.
Result<std::vector<Attribute>> split_attributes(std::string_view text, char separator) {
  std::vector<Attribute> out;
  Attribute current;
  std::string* field = &current.type;
  std::size_t value_end = 0;  // the value's length up to its last escaped character
  bool next_joins = false;
  auto finish = [&]() -> Result<void> {
    if (field == &current.type) return Error{"'" + trimmed(current.type) + "' has no '=' (TYPE=VALUE)"};
    current.type = trimmed(current.type);
    const auto end = std::max(value_end, current.value.find_last_not_of(' ') + 1);
    current.value.resize(std::min(end, current.value.size()));
    if (current.type.empty()) return Error{"an attribute without a type before '='"};
    if (current.value.empty()) return Error{"attribute " + current.type + " has no value"};
    current.joins_previous = next_joins;
    out.push_back(std::move(current));
    current = Attribute{};
    field = &current.type;
    value_end = 0;
    return {};
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\\') {
      if (i + 1 >= text.size()) return Error{"a backslash ends the subject"};
      const int high = hex_digit(text[i + 1]);
      const int low = i + 2 < text.size() ? hex_digit(text[i + 2]) : -1;
      if (high >= 0 && low >= 0) {
        field->push_back(static_cast<char>(high * 16 + low));
        i += 2;
      } else {
        field->push_back(text[++i]);
      }
      if (field == &current.value) value_end = current.value.size();
    } else if (c == separator || (c == '+' && separator == ',')) {
      if (auto done = finish(); !done) return done.error();
      next_joins = c == '+';
    } else if (c == '=' && field == &current.type) {
      field = &current.value;
    } else if (field == &current.value && current.value.empty() && c == ' ') {
      continue;  // spaces after '='
    } else {
      if (field == &current.value && current.value.empty() && c == '#' && separator == ',')
        return Error{"attribute " + trimmed(current.type) + ": a value in #hex (BER) form is not supported"};
      field->push_back(c);
    }
  }
  if (auto done = finish(); !done) return done.error();
  return out;
}

// The attributes in DER order (most general first), whichever form `text` is in.
Result<std::vector<Attribute>> attributes_of(std::string_view text) {
  const std::string whole = trimmed(text);
  if (whole.empty()) return Error{"an empty subject"};
  if (whole.front() == '/') {  // OpenSSL's one-line form: already in DER order
    auto attributes = split_attributes(std::string_view(whole).substr(1), '/');
    if (!attributes) return attributes.error();
    return attributes;
  }
  auto attributes = split_attributes(whole, ',');
  if (!attributes) return attributes.error();
  // RFC 2253 writes the RDNs most specific first: reverse the RDNs, keeping each one's attributes.
  std::vector<std::vector<Attribute>> rdns;
  for (Attribute& a : attributes.value()) {
    if (!a.joins_previous || rdns.empty()) rdns.emplace_back();
    rdns.back().push_back(std::move(a));
  }
  std::vector<Attribute> out;
  for (auto rdn = rdns.rbegin(); rdn != rdns.rend(); ++rdn) {
    for (std::size_t i = 0; i < rdn->size(); ++i) {
      (*rdn)[i].joins_previous = i > 0;
      out.push_back(std::move((*rdn)[i]));
    }
  }
  return out;
}

bool printable_string(const std::string& value) {
  return std::all_of(value.begin(), value.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           std::string_view(" '()+,-./:=?").find(c) != std::string_view::npos;
  });
}

std::string subject_openssl_reason() {
  const unsigned long code = ERR_peek_last_error();
  ERR_clear_error();
  const char* reason = code != 0 ? ERR_reason_error_string(code) : nullptr;
  return reason != nullptr ? reason : "unknown reason";
}

// One attribute and the string types it may be encoded with; the first is OpenSSL's own choice
// (what `openssl req -subj` writes).
struct EncodedAttribute {
  Object type;
  std::vector<int> string_types;
  bool joins_previous = false;
  std::string value;
};

Result<EncodedAttribute> encoded(const Attribute& a) {
  EncodedAttribute out;
  out.type.reset(OBJ_txt2obj(a.type.c_str(), 0));
  if (!out.type) {
    ERR_clear_error();
    return Error{"unknown attribute type '" + a.type + "' (a name such as CN, O, OU, C or a dotted OID)"};
  }
  const auto* bytes = reinterpret_cast<const unsigned char*>(a.value.data());
  const Entry chosen(
      X509_NAME_ENTRY_create_by_OBJ(nullptr, out.type.get(), MBSTRING_UTF8, bytes, static_cast<int>(a.value.size())));
  if (!chosen) return Error{"attribute " + a.type + ": " + subject_openssl_reason()};
  out.string_types.push_back(ASN1_STRING_type(X509_NAME_ENTRY_get_data(chosen.get())));
  for (const int other : {V_ASN1_UTF8STRING, V_ASN1_PRINTABLESTRING}) {
    if (other == V_ASN1_PRINTABLESTRING && !printable_string(a.value)) continue;
    if (std::find(out.string_types.begin(), out.string_types.end(), other) == out.string_types.end())
      out.string_types.push_back(other);
  }
  out.joins_previous = a.joins_previous;
  out.value = a.value;
  return out;
}

// The name with attribute i encoded as string_types[choice[i]]; null when OpenSSL refuses it.
Name build(const std::vector<EncodedAttribute>& attributes, const std::vector<std::size_t>& choice) {
  Name name(X509_NAME_new());
  for (std::size_t i = 0; name && i < attributes.size(); ++i) {
    const EncodedAttribute& a = attributes[i];
    const Entry entry(X509_NAME_ENTRY_create_by_OBJ(nullptr, a.type.get(), a.string_types[choice[i]],
                                                    reinterpret_cast<const unsigned char*>(a.value.data()),
                                                    static_cast<int>(a.value.size())));
    if (!entry || X509_NAME_add_entry(name.get(), entry.get(), -1, a.joins_previous ? -1 : 0) != 1) name.reset();
  }
  return name;
}

Result<SubjectKeyPrefix> prefix_of(X509_NAME* name) {
  unsigned char* der = nullptr;
  const int length = i2d_X509_NAME(name, &der);
  if (length <= 0) return Error{"cannot encode it: " + subject_openssl_reason()};
  const SubjectKeyPrefix prefix = subject_key_prefix({der, static_cast<std::size_t>(length)});
  OPENSSL_free(der);
  return prefix;
}

// Every choice of string types (attribute i: 0 .. types[i]-1), up to kMaxEncodings; beyond, the
// uniform ones.
std::vector<std::vector<std::size_t>> choices_of(const std::vector<EncodedAttribute>& attributes) {
  std::size_t total = 1;
  for (const EncodedAttribute& a : attributes) total = std::min(total * a.string_types.size(), kMaxEncodings + 1);
  std::vector<std::vector<std::size_t>> out;
  if (total <= kMaxEncodings) {
    std::vector<std::size_t> choice(attributes.size(), 0);
    for (std::size_t n = 0; n < total; ++n) {
      out.push_back(choice);
      for (std::size_t i = 0; i < choice.size() && ++choice[i] == attributes[i].string_types.size(); ++i) choice[i] = 0;
    }
    return out;
  }
  out.emplace_back(attributes.size(), 0);
  for (const int uniform : {V_ASN1_UTF8STRING, V_ASN1_PRINTABLESTRING}) {
    std::vector<std::size_t> choice;
    for (const EncodedAttribute& a : attributes) {
      const auto it = std::find(a.string_types.begin(), a.string_types.end(), uniform);
      choice.push_back(it == a.string_types.end() ? 0 : static_cast<std::size_t>(it - a.string_types.begin()));
    }
    out.push_back(std::move(choice));
  }
  return out;
}

}  // namespace

SubjectKeyPrefix subject_key_prefix(std::span<const std::uint8_t> der_name) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  SubjectKeyPrefix out{};
  if (EVP_Digest(der_name.data(), der_name.size(), md, &length, EVP_sha256(), nullptr) != 1 || length < 6) return out;
  // A 1 bit, then the digest's first 47 bits.
  out[0] = static_cast<std::uint8_t>(0x80 | (md[0] >> 1));
  for (std::size_t i = 1; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>((md[i - 1] << 7) | (md[i] >> 1));
  return out;
}

Result<CertificateSubject> parse_certificate_subject(std::string_view text) {
  auto attributes = attributes_of(text);
  if (!attributes) return attributes.error();
  if (attributes.value().size() > kMaxAttributes)
    return Error{"more than " + std::to_string(kMaxAttributes) + " attributes"};
  std::vector<EncodedAttribute> encodings;
  for (const Attribute& a : attributes.value()) {
    auto e = encoded(a);
    if (!e) return e.error();
    encodings.push_back(std::move(e).value());
  }
  CertificateSubject out;
  for (const std::vector<std::size_t>& choice : choices_of(encodings)) {
    const Name name = build(encodings, choice);
    if (!name) return Error{"cannot build the name: " + subject_openssl_reason()};
    if (out.text.empty()) {
      char line[1024];
      X509_NAME_oneline(name.get(), line, sizeof line);
      out.text = line;
    }
    auto prefix = prefix_of(name.get());
    if (!prefix) return prefix.error();
    if (std::find(out.prefixes.begin(), out.prefixes.end(), prefix.value()) == out.prefixes.end())
      out.prefixes.push_back(prefix.value());
  }
  return out;
}

bool holds_subject(const CertificateSubject& subject, std::span<const std::uint8_t> guid_prefix) {
  if (guid_prefix.size() < SubjectKeyPrefix{}.size()) return false;
  return std::any_of(subject.prefixes.begin(), subject.prefixes.end(),
                     [&](const SubjectKeyPrefix& p) { return std::equal(p.begin(), p.end(), guid_prefix.begin()); });
}

}  // namespace cosmic

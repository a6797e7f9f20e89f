// Certificate subjects (cosmic/certificate_subject.hpp): both written forms, the errors, and the
// PKI-DH participant key prefix against values computed apart from OpenSSL's library: certificates
// made with the openssl command line, their subject's DER cut out of the certificate and hashed by
// Python's hashlib (the key rule written out again in Python).
#include "cosmic/certificate_subject.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace cosmic {
namespace {

std::string run(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  std::array<char, 256> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) out += buffer.data();
  ::pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string hex(const SubjectKeyPrefix& p) {
  std::string out;
  char byte[4];
  for (const auto b : p) {
    std::snprintf(byte, sizeof byte, "%s%02x", out.empty() ? "" : ".", b);
    out += byte;
  }
  return out;
}

// The subject's DER in a PEM certificate (the 6th element of tbsCertificate, after the explicit
// version), SHA-256 by hashlib, then a 1 bit and the digest's first 47 bits: "b3.18.4a.80.e9.71".
constexpr const char* kPrefixScript = R"PY(
import hashlib, subprocess, sys
der = subprocess.run(["openssl", "x509", "-in", sys.argv[1], "-outform", "DER"], capture_output=True, check=True).stdout
def tlv(b, i):
    length = b[i + 1]; i += 2
    if length & 0x80:
        n = length & 0x7f; length = int.from_bytes(b[i:i + n], "big"); i += n
    return i, length
i, _ = tlv(der, 0)
i, length = tlv(der, i)
fields, end = [], i + length
while i < end:
    start = i; i, length = tlv(der, i); i += length; fields.append((der[start], der[start:i]))
subject = fields[(1 if fields[0][0] == 0xA0 else 0) + 4][1]
md = hashlib.sha256(subject).digest()
key = [0x80 | (md[0] >> 1)] + [((md[k] << 7) | (md[k + 1] >> 1)) & 0xFF for k in range(5)]
print(".".join("%02x" % x for x in key))
)PY";

class CertificateSubjectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / ("subject_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::FILE* script = std::fopen((dir_ / "prefix.py").c_str(), "w");
    ASSERT_NE(script, nullptr);
    std::fputs(kPrefixScript, script);
    std::fclose(script);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // A self-signed certificate for `subject` (one-line form); `string_mask` as openssl's config
  // takes it ("utf8only", OpenSSL's default, or "default": PrintableString where it can).
  std::string certificate(const std::string& name, const std::string& subject, const std::string& string_mask) {
    const std::string config = (dir_ / (name + ".cnf")).string();
    std::FILE* f = std::fopen(config.c_str(), "w");
    std::fprintf(f, "[req]\ndistinguished_name=dn\nstring_mask=%s\n[dn]\n", string_mask.c_str());
    std::fclose(f);
    const std::string pem = (dir_ / (name + ".pem")).string();
    const std::string command =
        "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 1 -config " + config +
        " -subj '" + subject + "' -keyout " + (dir_ / (name + "_key.pem")).string() + " -out " + pem +
        " >/dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return pem;
  }
  std::string python_prefix(const std::string& pem) {
    return run("/usr/bin/python3 " + (dir_ / "prefix.py").string() + " " + pem);
  }
  std::string rfc2253_subject(const std::string& pem) {
    const std::string line = run("openssl x509 -in " + pem + " -noout -subject -nameopt RFC2253");
    return line.substr(line.find('=') + 1);  // "subject=CN=...,O=..."
  }

  std::filesystem::path dir_;
};

bool has_prefix(const CertificateSubject& s, const std::string& expected) {
  for (const SubjectKeyPrefix& p : s.prefixes) {
    if (hex(p) == expected) return true;
  }
  return false;
}

TEST_F(CertificateSubjectTest, TheKeyPrefixIsTheOneTheOpensslCertificateGivesInBothForms) {
  const std::string pem = certificate("b", "/O=cosmic/CN=gateway-b", "utf8only");
  const std::string expected = python_prefix(pem);
  ASSERT_EQ(expected.size(), 17u) << expected;
  const std::string rfc2253 = rfc2253_subject(pem);
  ASSERT_EQ(rfc2253, "CN=gateway-b,O=cosmic");
  for (const std::string& text :
       {rfc2253, std::string("/O=cosmic/CN=gateway-b"), std::string(" CN=gateway-b, O=cosmic ")}) {
    auto parsed = parse_certificate_subject(text);
    ASSERT_TRUE(parsed) << text << ": " << parsed.error().text;
    EXPECT_EQ(parsed.value().text, "/O=cosmic/CN=gateway-b") << text;
    EXPECT_TRUE(has_prefix(parsed.value(), expected)) << text << " does not give " << expected;
    // OpenSSL's own choice (UTF8String) comes first.
    EXPECT_EQ(hex(parsed.value().prefixes.front()), expected) << text;
  }
}

// The participant key Fast DDS 2.9.1 gave the test PKI's gateway-a (/O=cosmic/CN=gateway-a, both
// attributes UTF8String): seen as b3.18.4a.80.e9.71.xx... in its GUID, and from the script above.
TEST_F(CertificateSubjectTest, GatewayAOfTheTestPkiHasTheKeyFastDdsGaveIt) {
  auto parsed = parse_certificate_subject("CN=gateway-a,O=cosmic");
  ASSERT_TRUE(parsed);
  EXPECT_EQ(hex(parsed.value().prefixes.front()), "b3.18.4a.80.e9.71");
  const std::array<std::uint8_t, 12> guid{0xb3, 0x18, 0x4a, 0x80, 0xe9, 0x71, 0xb1, 0x6b, 0xde, 0x75, 0xa6, 0xd8};
  EXPECT_TRUE(holds_subject(parsed.value(), guid));
  auto other = parse_certificate_subject("CN=gateway-b,O=cosmic");
  ASSERT_TRUE(other);
  EXPECT_FALSE(holds_subject(other.value(), guid));
  EXPECT_FALSE(holds_subject(parsed.value(), std::span(guid).first(5)));
}

// A CA that writes PrintableString where it can (OpenSSL's string_mask "default", many others'
// habit) gives another DER, hence another key: it is among the subject's keys too.
TEST_F(CertificateSubjectTest, APrintableStringCertificateOfTheSameSubjectMatchesToo) {
  const std::string utf8 = python_prefix(certificate("u", "/O=cosmic/CN=gateway b", "utf8only"));
  const std::string printable = python_prefix(certificate("p", "/O=cosmic/CN=gateway b", "default"));
  ASSERT_NE(utf8, printable) << "the two certificates encode the subject alike; the test shows nothing";
  auto parsed = parse_certificate_subject("CN=gateway b,O=cosmic");
  ASSERT_TRUE(parsed);
  EXPECT_TRUE(has_prefix(parsed.value(), utf8));
  EXPECT_TRUE(has_prefix(parsed.value(), printable));
  // An underscore is no PrintableString character: CN is a UTF8String then.
  const std::string underscore = python_prefix(certificate("x", "/O=cosmic/CN=gateway_b", "utf8only"));
  auto only_utf8 = parse_certificate_subject("/O=cosmic/CN=gateway_b");
  ASSERT_TRUE(only_utf8);
  EXPECT_TRUE(has_prefix(only_utf8.value(), underscore));
}

TEST_F(CertificateSubjectTest, EscapesAndMultiValuedNamesFollowRfc2253) {
  const std::string pem = certificate("e", "/O=cosmic, inc./CN=gateway\\+b", "utf8only");
  auto escaped = parse_certificate_subject("CN=gateway\\+b,O=cosmic\\, inc.");
  ASSERT_TRUE(escaped) << escaped.error().text;
  EXPECT_EQ(escaped.value().text, "/O=cosmic, inc./CN=gateway\\+b");  // as OpenSSL prints it
  EXPECT_TRUE(has_prefix(escaped.value(), python_prefix(pem)));
  auto hex_escape = parse_certificate_subject("CN=gateway\\2bb,O=cosmic\\2c inc.");
  ASSERT_TRUE(hex_escape);
  EXPECT_EQ(hex_escape.value().prefixes, escaped.value().prefixes);
  // In the one-line form a '+' is the value's own, escaped or not (OpenSSL prints it escaped).
  for (const char* text : {"/O=cosmic, inc./CN=gateway+b", "/O=cosmic, inc./CN=gateway\\+b"}) {
    auto one_line = parse_certificate_subject(text);
    ASSERT_TRUE(one_line) << text;
    EXPECT_EQ(one_line.value().prefixes, escaped.value().prefixes) << text;
  }
  // A multi-valued RDN (CN and OU in one) is another name than two RDNs.
  auto joined = parse_certificate_subject("CN=a+OU=b,O=cosmic");
  auto apart = parse_certificate_subject("CN=a,OU=b,O=cosmic");
  ASSERT_TRUE(joined && apart);
  EXPECT_NE(joined.value().prefixes.front(), apart.value().prefixes.front());
}

TEST_F(CertificateSubjectTest, AMalformedSubjectSaysWhatIsWrong) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "an empty subject"},
      {"CN=gateway-b,O", "'O' has no '='"},
      {"/O=cosmic/CN=", "attribute CN has no value"},
      {"XQ=1,O=cosmic", "unknown attribute type 'XQ'"},
      {"=x", "an attribute without a type"},
      {"CN=a\\", "a backslash ends the subject"},
      {"CN=#0403616263", "#hex (BER) form is not supported"},
      {"C=USA", "attribute C: "},
  };
  for (const auto& [text, why] : cases) {
    auto parsed = parse_certificate_subject(text);
    ASSERT_FALSE(parsed) << text;
    EXPECT_NE(parsed.error().text.find(why), std::string::npos) << text << ": " << parsed.error().text;
  }
}

}  // namespace
}  // namespace cosmic

// HMAC-SHA256 through MessageAuth against RFC 4231's test cases and against the openssl command
// line (an implementation we did not write) over messages in several parts.
#include "cosmic/message_auth.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace cosmic {
namespace {

std::vector<std::uint8_t> mac_test_bytes(std::size_t n, std::uint8_t value) {
  return std::vector<std::uint8_t>(n, value);
}

std::string mac_test_hex(std::span<const std::uint8_t> bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const std::uint8_t b : bytes) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

std::string hmac_of(std::span<const std::uint8_t> key, std::initializer_list<std::span<const std::uint8_t>> parts) {
  auto mac = MessageAuth::make(MacAlgorithm::hmac_sha256, key);
  EXPECT_TRUE(mac) << mac.error().text;
  MacBytes out{};
  EXPECT_TRUE(mac.value().compute(parts, out));
  return mac_test_hex(std::span(out.data(), mac.value().size()));
}

std::span<const std::uint8_t> text_bytes(std::string_view text) {
  return std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

// RFC 4231, test cases 1, 3 and 4 (the others' keys are shorter than 16 bytes or longer than 64).
TEST(MessageAuth, HmacSha256MatchesRfc4231) {
  EXPECT_EQ(hmac_of(mac_test_bytes(20, 0x0b), {text_bytes("Hi There")}),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
  const auto dd = mac_test_bytes(50, 0xdd);
  EXPECT_EQ(hmac_of(mac_test_bytes(20, 0xaa), {dd}),
            "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe");
  std::vector<std::uint8_t> key4;
  for (std::uint8_t b = 1; b <= 25; ++b) key4.push_back(b);
  const auto cd = mac_test_bytes(50, 0xcd);
  EXPECT_EQ(hmac_of(key4, {std::span(cd).first(7), std::span(cd).subspan(7)}),
            "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b");
}

TEST(MessageAuth, EachComputationStartsFromTheKeyAlone) {
  const auto key = mac_test_bytes(20, 0x0b);
  auto mac = MessageAuth::make(MacAlgorithm::hmac_sha256, key).value();
  MacBytes first{};
  MacBytes second{};
  ASSERT_TRUE(mac.compute({text_bytes("something else first")}, first));
  ASSERT_TRUE(mac.compute({text_bytes("Hi There")}, second));
  EXPECT_EQ(mac_test_hex(std::span(second.data(), 32)),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
}

// The openssl command line's HMAC of the same bytes, for random keys and messages.
TEST(MessageAuth, HmacSha256AgreesWithTheOpensslCommandLine) {
  std::mt19937 random(36);
  const std::string file = testing::TempDir() + "message_auth_input.bin";
  for (const std::size_t length : {0u, 1u, 63u, 64u, 65u, 1500u}) {
    std::vector<std::uint8_t> key(32);
    std::vector<std::uint8_t> message(length);
    for (auto& b : key) b = static_cast<std::uint8_t>(random());
    for (auto& b : message) b = static_cast<std::uint8_t>(random());
    std::ofstream(file, std::ios::binary)
        .write(reinterpret_cast<const char*>(message.data()), static_cast<std::streamsize>(message.size()));
    const std::string command =
        "openssl mac -digest SHA256 -macopt hexkey:" + mac_test_hex(key) + " -in " + file + " HMAC 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    char line[256] = {};
    const bool read = std::fgets(line, sizeof line, pipe) != nullptr;
    ASSERT_EQ(::pclose(pipe), 0) << "openssl mac failed (setup installs openssl): " << line;
    ASSERT_TRUE(read);
    std::string expected(line);
    while (!expected.empty() && (expected.back() == '\n' || expected.back() == '\r')) expected.pop_back();
    for (auto& c : expected) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto half = message.size() / 2;
    EXPECT_EQ(hmac_of(key, {std::span(message).first(half), std::span(message).subspan(half)}), expected)
        << "message of " << length << " bytes";
  }
}

TEST(MessageAuth, RefusesKeysOfTheWrongSize) {
  EXPECT_EQ(MessageAuth::make(MacAlgorithm::hmac_sha256, mac_test_bytes(15, 1)).error().text,
            "an HMAC-SHA256 key has 16 to 64 bytes, this one 15");
  EXPECT_FALSE(MessageAuth::make(MacAlgorithm::hmac_sha256, mac_test_bytes(65, 1)));
  EXPECT_EQ(MessageAuth::make(MacAlgorithm::aes128_cmac, mac_test_bytes(32, 1)).error().text,
            "an AES-128-CMAC key has 16 bytes, this one 32");
}

TEST(MessageAuth, TagsCompareOnlyTheirTruncatedBytes) {
  const std::vector<std::uint8_t> a{1, 2, 3, 4};
  const std::vector<std::uint8_t> b{1, 2, 3, 5};
  EXPECT_TRUE(tags_equal(a, b, 3));
  EXPECT_FALSE(tags_equal(a, b, 4));
  EXPECT_FALSE(tags_equal(a, std::span(b).first(2), 3));
}

}  // namespace
}  // namespace cosmic

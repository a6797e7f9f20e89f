// Key files' text and mode (cosmic/secret_key.hpp).
#include "cosmic/secret_key.hpp"

#include <gtest/gtest.h>

namespace cosmic {
namespace {

TEST(SecretKey, ReadsTheHexOpensslRandWrites) {
  const auto key = parse_key_text("00ff10A0\n", 4, 64);
  ASSERT_TRUE(key) << key.error().text;
  const std::vector<std::uint8_t> expected{0x00, 0xff, 0x10, 0xa0};
  EXPECT_TRUE(std::equal(key.value().bytes().begin(), key.value().bytes().end(), expected.begin(), expected.end()));
}

TEST(SecretKey, WhiteSpaceBetweenBytesIsIgnored) {
  const auto key = parse_key_text("  01 02\t03\r\n04  \n", 4, 4);
  ASSERT_TRUE(key) << key.error().text;
  EXPECT_EQ(key.value().size(), 4u);
}

TEST(SecretKey, RefusesWhatIsNoKeyWithoutQuotingIt) {
  const auto not_hex = parse_key_text("0011zz33", 1, 64);
  ASSERT_FALSE(not_hex);
  EXPECT_EQ(not_hex.error().text, "byte 5 is not a hexadecimal digit");
  EXPECT_EQ(not_hex.error().text.find("zz"), std::string::npos);
  EXPECT_EQ(parse_key_text("001", 1, 64).error().text, "an odd number of hexadecimal digits");
  EXPECT_EQ(parse_key_text("0 011", 1, 64).error().text,
            "a hexadecimal digit stands alone before the white space at byte 2");
  EXPECT_EQ(parse_key_text("0011", 16, 64).error().text,
            "2 bytes of key, fewer than 16 (openssl rand -hex 16 writes one)");
  EXPECT_EQ(parse_key_text("001122", 1, 2).error().text, "more than 2 bytes of key");
  EXPECT_FALSE(parse_key_text("", 1, 64));
}

TEST(SecretKey, OnlyTheOwnerMayReadOrWriteAKeyFile) {
  EXPECT_TRUE(check_key_file_mode(0100600));
  EXPECT_TRUE(check_key_file_mode(0100400));
  EXPECT_EQ(check_key_file_mode(0100640).error().text,
            "group or others may read or write it (mode 0640; chmod 600 it)");
  EXPECT_FALSE(check_key_file_mode(0100604));
  EXPECT_FALSE(check_key_file_mode(0100602));
  EXPECT_FALSE(check_key_file_mode(0100620));
}

TEST(SecretKey, MovingLeavesNothingBehind) {
  SecretKey key = parse_key_text("0102030405060708", 8, 8).value();
  SecretKey moved(std::move(key));
  EXPECT_EQ(moved.size(), 8u);
  EXPECT_TRUE(key.empty());  // NOLINT(bugprone-use-after-move): what a move leaves is the point
}

}  // namespace
}  // namespace cosmic

// The LCM authentication trailer (cosmic/lcm_auth.hpp) and the replay window under it.
#include "cosmic/lcm_auth.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "cosmic/replay_window.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kNow = 1'790'000'000'000'000'000;  // some wall clock in 2026

std::vector<std::uint8_t> auth_test_key(std::uint8_t seed) {
  std::vector<std::uint8_t> key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(seed + i * 7);
  return key;
}

// A message as the sender puts it on the wire: its parts, then the trailer.
std::vector<std::uint8_t> signed_message(LcmAuthSigner& signer, std::string_view channel,
                                         const std::vector<std::uint8_t>& body, std::int64_t sent_ns = kNow) {
  const std::span<const std::uint8_t> head = std::span(body).first(body.size() / 2);
  const std::span<const std::uint8_t> tail = std::span(body).subspan(body.size() / 2);
  const std::array<std::span<const std::uint8_t>, 2> parts{head, tail};
  LcmAuthTrailer trailer{};
  EXPECT_TRUE(signer.sign(channel, parts, sent_ns, trailer));
  std::vector<std::uint8_t> out = body;
  out.insert(out.end(), trailer.begin(), trailer.end());
  return out;
}

struct LcmAuthPair {
  LcmAuthSigner signer = LcmAuthSigner::make(auth_test_key(1), 0x1122334455667788).value();
  LcmAuthVerifier verifier = LcmAuthVerifier::make(auth_test_key(1), 500ms).value();
};

const std::vector<std::uint8_t> kBody{0x94, 0xce, 0xe8, 0xbe, 1, 2, 3, 4, 5, 6, 7, 8, 9};

TEST(LcmAuth, TheTrailerIsTheDocumentedLayout) {
  auto signer = LcmAuthSigner::make(auth_test_key(1), 0x1122334455667788).value();
  const auto wire = signed_message(signer, "obstacle", kBody, 0x0102030405060708);
  ASSERT_EQ(wire.size(), kBody.size() + 40);
  const std::vector<std::uint8_t> head(wire.begin() + kBody.size(), wire.begin() + kBody.size() + 24);
  const std::vector<std::uint8_t> expected_head{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0, 0, 0, 0,
                                                0,    0,    0,    1,    1,    2,    3,    4,    5, 6, 7, 8};
  EXPECT_EQ(head, expected_head);
  // The tag: HMAC-SHA256's first 16 bytes over name length, name, message and the trailer's head.
  auto mac = MessageAuth::make(MacAlgorithm::hmac_sha256, auth_test_key(1)).value();
  const std::uint8_t length = 8;
  const std::string name = "obstacle";
  MacBytes tag{};
  ASSERT_TRUE(mac.compute({std::span(&length, 1), std::span(reinterpret_cast<const std::uint8_t*>(name.data()), 8),
                           std::span(kBody), std::span(head)},
                          tag));
  EXPECT_TRUE(std::equal(tag.begin(), tag.begin() + 16, wire.end() - 16));
}

TEST(LcmAuth, AnAuthenticMessageIsTakenOnceWithoutItsTrailer) {
  LcmAuthPair pair;
  const auto wire = signed_message(pair.signer, "obstacle", kBody);
  const LcmAuthCheck first = pair.verifier.check("obstacle", wire, kNow + 1'000'000);
  EXPECT_EQ(first.verdict, LcmAuthVerdict::authentic);
  EXPECT_EQ(first.message_size, kBody.size());
  EXPECT_EQ(first.sender, 0x1122334455667788u);
  EXPECT_EQ(first.skew_ns, -1'000'000);
  EXPECT_EQ(pair.verifier.check("obstacle", wire, kNow + 2'000'000).verdict, LcmAuthVerdict::replayed);
}

TEST(LcmAuth, AnyAlteredByteMakesItUnauthenticated) {
  LcmAuthPair pair;
  const auto wire = signed_message(pair.signer, "obstacle", kBody);
  for (std::size_t i = 0; i < wire.size(); ++i) {
    auto altered = wire;
    altered[i] ^= 0x01;
    EXPECT_EQ(pair.verifier.check("obstacle", altered, kNow).verdict, LcmAuthVerdict::unauthenticated) << "byte " << i;
  }
  // None of the refused ones moved the window: the original is still new.
  EXPECT_EQ(pair.verifier.check("obstacle", wire, kNow).verdict, LcmAuthVerdict::authentic);
}

TEST(LcmAuth, AnotherChannelAnotherKeyOrATruncationIsUnauthenticated) {
  LcmAuthPair pair;
  const auto wire = signed_message(pair.signer, "obstacle", kBody);
  EXPECT_EQ(pair.verifier.check("drive", wire, kNow).verdict, LcmAuthVerdict::unauthenticated);
  auto stranger = LcmAuthVerifier::make(auth_test_key(2), 500ms).value();
  EXPECT_EQ(stranger.check("obstacle", wire, kNow).verdict, LcmAuthVerdict::unauthenticated);
  EXPECT_EQ(pair.verifier.check("obstacle", std::span(wire).first(wire.size() - 1), kNow).verdict,
            LcmAuthVerdict::unauthenticated);
  EXPECT_EQ(pair.verifier.check("obstacle", std::span(wire).first(39), kNow).verdict, LcmAuthVerdict::unauthenticated);
  // An unsigned envelope, as any LCM program sends it.
  EXPECT_EQ(pair.verifier.check("obstacle", kBody, kNow).verdict, LcmAuthVerdict::unauthenticated);
}

TEST(LcmAuth, OutsideTheTimeWindowIsAReplayEvenForANewReceiver) {
  LcmAuthPair pair;
  const auto old = signed_message(pair.signer, "obstacle", kBody, kNow - 600'000'000);
  const auto future = signed_message(pair.signer, "obstacle", kBody, kNow + 600'000'000);
  const auto edge = signed_message(pair.signer, "obstacle", kBody, kNow - 500'000'000);
  EXPECT_EQ(pair.verifier.check("obstacle", old, kNow).verdict, LcmAuthVerdict::replayed);
  EXPECT_EQ(pair.verifier.check("obstacle", future, kNow).verdict, LcmAuthVerdict::replayed);
  EXPECT_EQ(pair.verifier.check("obstacle", edge, kNow).verdict, LcmAuthVerdict::authentic);
}

// A holder of the key picks sent_ns freely: the extremes are refused, never an overflow (UBSan).
TEST(LcmAuth, SigningTimesAtTheEndsOfTheClockAreOutsideTheWindow) {
  LcmAuthPair pair;
  for (const std::int64_t sent : {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max(),
                                  std::int64_t{0}, std::int64_t{-1}}) {
    const LcmAuthCheck checked =
        pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody, sent), kNow);
    EXPECT_EQ(checked.verdict, LcmAuthVerdict::replayed) << sent;
  }
  EXPECT_EQ(
      pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody, kNow + 500'000'000), kNow).verdict,
      LcmAuthVerdict::authentic);  // the window's far edge is inside
}

// Another holder of the key writes under a sender's number with a huge sequence: that sender's
// next messages count as replayed, but only until its entry expires, not for good.
TEST(LcmAuth, ASenderNumberPushedUpByAnotherHolderRecoversAfterTheWindow) {
  LcmAuthPair pair;
  ASSERT_EQ(pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::authentic);
  // The same sender number, sequence 2^64 - 1: a hand-made trailer, as a holder of the key could.
  auto mac = MessageAuth::make(MacAlgorithm::hmac_sha256, auth_test_key(1)).value();
  std::vector<std::uint8_t> head{0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0xff, 0xff, 0xff, 0xff,
                                 0xff, 0xff, 0xff, 0xff, 0,    0,    0,    0,    0,    0,    0,    0};
  for (int i = 0; i < 8; ++i)
    head[16 + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(kNow) >> (56 - 8 * i));
  const std::uint8_t length = 8;
  MacBytes tag{};
  ASSERT_TRUE(mac.compute({std::span(&length, 1), std::span(reinterpret_cast<const std::uint8_t*>("obstacle"), 8),
                           std::span(kBody), std::span(head)},
                          tag));
  std::vector<std::uint8_t> pushed = kBody;
  pushed.insert(pushed.end(), head.begin(), head.end());
  pushed.insert(pushed.end(), tag.begin(), tag.begin() + 16);
  ASSERT_EQ(pair.verifier.check("obstacle", pushed, kNow).verdict, LcmAuthVerdict::authentic);
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::replayed);
  const std::int64_t later = kNow + 600'000'000;  // past the window after the pushed message
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody, later), later).verdict,
            LcmAuthVerdict::authentic);
}

TEST(LcmAuth, ACrowdedTableSaysSo) {
  LcmAuthPair pair;
  for (std::uint64_t id = 1; id <= LcmAuthVerifier::kMaxSenders; ++id) {
    auto signer = LcmAuthSigner::make(auth_test_key(1), id).value();
    ASSERT_FALSE(pair.verifier.check("obstacle", signed_message(signer, "obstacle", kBody), kNow).crowded);
  }
  auto one_more = LcmAuthSigner::make(auth_test_key(1), 100000).value();
  EXPECT_TRUE(pair.verifier.check("obstacle", signed_message(one_more, "obstacle", kBody), kNow).crowded);
}

TEST(LcmAuth, ReorderedWithinTheWindowIsTakenBelowItIsNot) {
  LcmAuthPair pair;
  std::vector<std::vector<std::uint8_t>> sent;
  for (int i = 0; i < 300; ++i) sent.push_back(signed_message(pair.signer, "obstacle", kBody));
  EXPECT_EQ(pair.verifier.check("obstacle", sent[299], kNow).verdict, LcmAuthVerdict::authentic);  // number 300
  EXPECT_EQ(pair.verifier.check("obstacle", sent[44], kNow).verdict, LcmAuthVerdict::authentic);   // 255 behind
  EXPECT_EQ(pair.verifier.check("obstacle", sent[43], kNow).verdict, LcmAuthVerdict::replayed);    // 256 behind
  EXPECT_EQ(pair.verifier.check("obstacle", sent[44], kNow).verdict, LcmAuthVerdict::replayed);
}

TEST(LcmAuth, ARestartedSenderIsANewSender) {
  LcmAuthPair pair;
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(pair.signer, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::authentic);
  auto restarted = LcmAuthSigner::make(auth_test_key(1), 0x99).value();
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(restarted, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::authentic);
}

TEST(LcmAuth, SendersAreForgottenAfterTheWindowAndBounded) {
  LcmAuthPair pair;
  for (std::uint64_t id = 1; id <= LcmAuthVerifier::kMaxSenders; ++id) {
    auto signer = LcmAuthSigner::make(auth_test_key(1), id).value();
    ASSERT_EQ(pair.verifier.check("obstacle", signed_message(signer, "obstacle", kBody), kNow).verdict,
              LcmAuthVerdict::authentic);
  }
  auto one_more = LcmAuthSigner::make(auth_test_key(1), 100000).value();
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(one_more, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::replayed);  // every entry in use within the window
  const std::int64_t later = kNow + 600'000'000;
  EXPECT_EQ(pair.verifier.check("obstacle", signed_message(one_more, "obstacle", kBody, later), later).verdict,
            LcmAuthVerdict::authentic);
}

// A key change: receivers accept the new key beside the old before senders sign with it, and the
// old beside the new until every sender changed over; a key in neither list still counts for nothing.
TEST(LcmAuth, DuringAKeyChangeTagsOfEitherKeyCount) {
  const auto old_key = auth_test_key(1);
  const auto new_key = auth_test_key(2);
  const std::span<const std::uint8_t> both[] = {old_key, new_key};
  auto verifier = LcmAuthVerifier::make(both, 500ms).value();
  auto old_signer = LcmAuthSigner::make(old_key, 1).value();
  auto new_signer = LcmAuthSigner::make(new_key, 2).value();
  auto stranger = LcmAuthSigner::make(auth_test_key(3), 3).value();
  EXPECT_EQ(verifier.check("obstacle", signed_message(old_signer, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::authentic);
  EXPECT_EQ(verifier.check("obstacle", signed_message(new_signer, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::authentic);
  EXPECT_EQ(verifier.check("obstacle", signed_message(stranger, "obstacle", kBody), kNow).verdict,
            LcmAuthVerdict::unauthenticated);
  EXPECT_FALSE(LcmAuthVerifier::make(std::span<const std::span<const std::uint8_t>>{}, 500ms));
}

TEST(LcmAuth, KeysAndWindowsAreChecked) {
  EXPECT_FALSE(LcmAuthSigner::make(std::vector<std::uint8_t>(8, 1), 1));
  EXPECT_EQ(LcmAuthVerifier::make(auth_test_key(1), 0ms).error().text, "the replay window must be longer than 0");
}

TEST(ReplayWindow, EachNumberOnceAndNothingBelowTheWindow) {
  ReplayWindow window;
  EXPECT_FALSE(window.accept(0));
  EXPECT_TRUE(window.accept(5));
  EXPECT_TRUE(window.accept(3));
  EXPECT_FALSE(window.accept(3));
  EXPECT_FALSE(window.accept(5));
  EXPECT_TRUE(window.accept(70));  // across a word
  EXPECT_FALSE(window.accept(5));
  EXPECT_TRUE(window.accept(4));
  EXPECT_TRUE(window.accept(1000));
  EXPECT_FALSE(window.accept(1000 - 256));
  EXPECT_TRUE(window.accept(1000 - 255));
  EXPECT_FALSE(window.accept(70));
  EXPECT_EQ(window.highest(), 1000u);
}

TEST(ReplayWindow, ShiftsKeepEveryMarkInPlaceAndAddNone) {
  // Against a plain set of what was accepted, over shifts of many sizes within the window: after
  // each, every accepted number within the window is refused and every other one is still new
  // (tried on a copy, so the window itself is not changed).
  for (const std::uint64_t stride : {7u, 11u}) {
    ReplayWindow window;
    std::vector<std::uint64_t> accepted;
    std::uint64_t next = 1;
    for (std::uint64_t step = 1; step < 300; step += stride) {
      next += step;
      ASSERT_TRUE(window.accept(next));
      accepted.push_back(next);
      for (std::uint64_t behind = 0; behind < ReplayWindow::kWidth && behind < next; ++behind) {
        const std::uint64_t number = next - behind;
        const bool taken = std::find(accepted.begin(), accepted.end(), number) != accepted.end();
        ReplayWindow copy = window;
        EXPECT_EQ(copy.accept(number), !taken) << number << " after " << next;
      }
    }
  }
}

}  // namespace
}  // namespace cosmic

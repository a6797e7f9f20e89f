// SecOC's secured PDU (cosmic/secoc.hpp): AES-128-CMAC against RFC 4493's examples, the codec's MAC
// against the `openssl mac` command line over the MAC input built here byte by byte, the layout,
// round trips, the receiver's reconstruction of truncated freshness values (epochs, lost frames,
// replays, the end of the 64-bit range), and what it refuses.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "cosmic/message_auth.hpp"
#include "cosmic/secoc.hpp"

namespace cosmic {
namespace {

using SecocBytes = std::vector<std::uint8_t>;
constexpr std::uint64_t kSecocMax = std::numeric_limits<std::uint64_t>::max();
constexpr std::string_view kSecocKeyHex = "00112233445566778899aabbccddeeff";

SecocBytes secoc_hex(std::string_view hex) {
  SecocBytes bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    bytes.push_back(static_cast<std::uint8_t>(std::stoul(std::string(hex.substr(i, 2)), nullptr, 16)));
  return bytes;
}

std::string secoc_to_hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text;
  for (const std::uint8_t b : bytes) text += {kDigits[b >> 4], kDigits[b & 15]};
  return text;
}

SecocBytes secoc_data(std::size_t size, unsigned seed = 7) {
  SecocBytes data(size);
  for (std::size_t i = 0; i < size; ++i) data[i] = static_cast<std::uint8_t>(seed * 31 + i * 17 + (i >> 3));
  return data;
}

SecocParameters secoc_params(unsigned mac_bits, unsigned freshness_bits, std::uint32_t data_id = 0x123) {
  return SecocParameters{data_id, mac_bits, freshness_bits, 4};
}

SecocSender secoc_sender(const SecocParameters& p, std::uint64_t start, std::string_view key = kSecocKeyHex) {
  Result<SecocSender> made = SecocSender::make(secoc_hex(key), p, start);
  if (!made) throw std::runtime_error(made.error().text);
  return std::move(made).value();
}

SecocReceiver secoc_receiver(const SecocParameters& p, std::uint64_t start, std::string_view key = kSecocKeyHex) {
  Result<SecocReceiver> made = SecocReceiver::make(secoc_hex(key), p, start);
  if (!made) throw std::runtime_error(made.error().text);
  return std::move(made).value();
}

// The secured PDU of `data` (empty when protect() refuses).
SecocBytes secoc_protect(SecocSender& sender, const SecocBytes& data) {
  SecocBytes out(data.size() + sender.overhead_bytes());
  const std::size_t written = sender.protect(data, out);
  out.resize(written);
  return out;
}

// Data ID || data || freshness, big-endian, built here independently of the codec.
SecocBytes secoc_mac_input(std::uint32_t data_id, const SecocBytes& data, std::uint64_t freshness) {
  SecocBytes input;
  for (int shift = 24; shift >= 0; shift -= 8) input.push_back(static_cast<std::uint8_t>(data_id >> shift));
  input.insert(input.end(), data.begin(), data.end());
  for (int shift = 56; shift >= 0; shift -= 8) input.push_back(static_cast<std::uint8_t>(freshness >> shift));
  return input;
}

// What `openssl mac ... CMAC` prints for `input`, in lower case, or the reason it printed nothing.
std::string secoc_openssl_cmac(std::string_view key_hex, const SecocBytes& input) {
  const std::string path = testing::TempDir() + "secoc_mac_input.bin";
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(input.data()), static_cast<std::streamsize>(input.size()));
  const std::string command =
      "openssl mac -cipher AES-128-CBC -macopt hexkey:" + std::string(key_hex) + " -in '" + path + "' CMAC 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return "popen failed";
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = ::pclose(pipe);
  std::remove(path.c_str());
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
  for (char& c : output) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return status == 0 ? output : "exit status " + std::to_string(status) + ": " + output;
}

TEST(SecocCmac, MessageAuthMatchesRfc4493Examples) {
  // RFC 4493 section 4 (= NIST SP 800-38B, D.1), AES-128.
  const std::string message =
      "6bc1bee22e409f96e93d7e117393172aae2d8a571e03ac9c9eb76fac45af8e51"
      "30c81c46a35ce411e5fbc1191a0a52eff69f2445df4f9b17ad2b417be66c3710";
  const std::vector<std::pair<std::size_t, std::string>> examples = {{0, "bb1d6929e95937287fa37d129b756746"},
                                                                     {16, "070a16b46b4d4144f79bdd9dd04a287c"},
                                                                     {40, "dfa66747de9ae63030ca32611497c827"},
                                                                     {64, "51f0bebf7e3b9d92fc49741779363cfe"}};
  Result<MessageAuth> auth =
      MessageAuth::make(MacAlgorithm::aes128_cmac, secoc_hex("2b7e151628aed2a6abf7158809cf4f3c"));
  ASSERT_TRUE(auth) << auth.error().text;
  for (const auto& [size, tag] : examples) {
    const SecocBytes m = secoc_hex(std::string_view(message).substr(0, size * 2));
    MacBytes out{};
    ASSERT_TRUE(auth.value().compute({std::span<const std::uint8_t>(m)}, out));
    EXPECT_EQ(secoc_to_hex(std::span(out).first(16)), tag) << size << " bytes";
    // The same message in three parts, back to back.
    const std::span<const std::uint8_t> all(m);
    const std::size_t a = size / 3, b = size / 2;
    MacBytes parted{};
    ASSERT_TRUE(auth.value().compute({all.first(a), all.subspan(a, b - a), all.subspan(b)}, parted));
    EXPECT_EQ(secoc_to_hex(std::span(parted).first(16)), tag) << size << " bytes in parts";
  }
}

TEST(SecocCodec, MacEqualsOpensslCommandLine) {
  ASSERT_EQ(std::system("command -v openssl >/dev/null 2>&1"), 0)
      << "openssl is not on PATH (scripts/setup installs it); this test needs it";
  struct Case {
    SecocParameters params;
    std::uint64_t start;
    std::size_t size;
  };
  const std::vector<Case> cases = {{secoc_params(24, 8, 0x123), 250, 0},
                                   {secoc_params(24, 8, 0x123), 255, 5},
                                   {secoc_params(32, 16, 0x7FF), 0xFFFF, 8},
                                   {secoc_params(64, 0, 0x42), 9, 12},
                                   {secoc_params(128, 64, 0x1ABCDEF0), 0x0102030405060708, 60}};
  for (const Case& c : cases) {
    SecocSender sender = secoc_sender(c.params, c.start);
    const SecocBytes data = secoc_data(c.size, static_cast<unsigned>(c.start));
    const SecocBytes pdu = secoc_protect(sender, data);
    ASSERT_EQ(pdu.size(), c.size + sender.overhead_bytes());
    const std::string expected = secoc_openssl_cmac(kSecocKeyHex, secoc_mac_input(c.params.data_id, data, c.start + 1));
    ASSERT_EQ(expected.size(), 32u) << expected;
    const std::size_t mac_bytes = c.params.mac_bits / 8;
    EXPECT_EQ(secoc_to_hex(std::span(pdu).last(mac_bytes)), expected.substr(0, mac_bytes * 2))
        << "mac_bits " << c.params.mac_bits << ", freshness " << c.start + 1 << ", " << c.size << " bytes";
  }
}

TEST(SecocCodec, SecuredPduIsDataThenTruncatedFreshnessThenMac) {
  const SecocBytes data = secoc_data(6);
  for (const auto& [mac_bits, fresh_bits, fresh_hex] : std::vector<std::tuple<unsigned, unsigned, std::string>>{
           {24, 8, "08"}, {32, 16, "0708"}, {64, 0, ""}, {128, 64, "0102030405060708"}}) {
    const SecocParameters p = secoc_params(mac_bits, fresh_bits, 0xA1B2C3D4);
    EXPECT_EQ(secoc_overhead_bytes(p), (mac_bits + fresh_bits) / 8);
    SecocSender sender = secoc_sender(p, 0x0102030405060707);
    const SecocBytes pdu = secoc_protect(sender, data);
    ASSERT_EQ(pdu.size(), data.size() + fresh_hex.size() / 2 + mac_bits / 8);
    EXPECT_EQ(sender.freshness(), 0x0102030405060708u);
    EXPECT_EQ(SecocBytes(pdu.begin(), pdu.begin() + 6), data);
    EXPECT_EQ(secoc_to_hex(std::span(pdu).subspan(6, fresh_hex.size() / 2)), fresh_hex);
    Result<MessageAuth> auth = MessageAuth::make(MacAlgorithm::aes128_cmac, secoc_hex(kSecocKeyHex));
    ASSERT_TRUE(auth);
    const SecocBytes input = secoc_mac_input(0xA1B2C3D4, data, 0x0102030405060708);
    MacBytes full{};
    ASSERT_TRUE(auth.value().compute({std::span<const std::uint8_t>(input)}, full));
    EXPECT_EQ(secoc_to_hex(std::span(pdu).last(mac_bits / 8)), secoc_to_hex(std::span(full).first(mac_bits / 8)));
  }
}

TEST(SecocCodec, RoundTripsForSeveralSizes) {
  for (const auto& [mac_bits, fresh_bits] :
       std::vector<std::pair<unsigned, unsigned>>{{24, 8}, {32, 16}, {64, 0}, {128, 64}, {8, 8}}) {
    const SecocParameters p = secoc_params(mac_bits, fresh_bits);
    SecocSender sender = secoc_sender(p, 1000);
    SecocReceiver receiver = secoc_receiver(p, 1000);
    for (std::size_t size = 0; size <= 60; ++size) {
      const SecocBytes data = secoc_data(size, mac_bits + fresh_bits);
      const SecocBytes pdu = secoc_protect(sender, data);
      ASSERT_EQ(pdu.size(), size + (mac_bits + fresh_bits) / 8);
      const SecocReading reading = receiver.verify(pdu);
      ASSERT_EQ(reading.status, SecocStatus::authentic) << mac_bits << "/" << fresh_bits << ", " << size << " bytes";
      EXPECT_EQ(reading.authentic_size, size);
      EXPECT_EQ(SecocBytes(pdu.begin(), pdu.begin() + static_cast<std::ptrdiff_t>(size)), data);
      EXPECT_EQ(reading.freshness, sender.freshness());
      EXPECT_EQ(receiver.freshness(), sender.freshness());
    }
  }
}

TEST(SecocCodec, ProtectsInPlaceAndRefusesTooSmallBuffers) {
  const SecocParameters p = secoc_params(32, 16);
  SecocSender sender = secoc_sender(p, 41);
  SecocSender twin = secoc_sender(p, 41);
  const SecocBytes data = secoc_data(10);
  SecocBytes small(data.size() + sender.overhead_bytes() - 1);
  EXPECT_EQ(sender.protect(data, small), 0u);
  EXPECT_EQ(sender.freshness(), 41u) << "a refused frame uses no freshness value";
  SecocBytes buffer = data;
  buffer.resize(data.size() + sender.overhead_bytes());
  ASSERT_EQ(sender.protect(std::span(buffer).first(data.size()), buffer), buffer.size());
  EXPECT_EQ(buffer, secoc_protect(twin, data));
  EXPECT_EQ(secoc_receiver(p, 41).verify(buffer).status, SecocStatus::authentic);
}

TEST(SecocFreshness, ReconstructsAcrossEpochBoundaries) {
  // 8 bits: the sender's counter runs 250..270, its low byte wraps after 255.
  const SecocParameters p8 = secoc_params(24, 8);
  SecocSender sender = secoc_sender(p8, 249);
  SecocReceiver receiver = secoc_receiver(p8, 249);
  for (std::uint64_t expected = 250; expected <= 270; ++expected) {
    const SecocBytes pdu = secoc_protect(sender, secoc_data(8, static_cast<unsigned>(expected)));
    ASSERT_EQ(pdu[8], static_cast<std::uint8_t>(expected & 0xFF));
    const SecocReading reading = receiver.verify(pdu);
    ASSERT_EQ(reading.status, SecocStatus::authentic) << "freshness " << expected;
    EXPECT_EQ(reading.freshness, expected);
    EXPECT_EQ(receiver.freshness(), expected);
  }
  // 16 bits across 0x10000.
  const SecocParameters p16 = secoc_params(32, 16);
  SecocSender sender16 = secoc_sender(p16, 0x1FFF0);
  SecocReceiver receiver16 = secoc_receiver(p16, 0x1FFF0);
  for (std::uint64_t expected = 0x1FFF1; expected <= 0x20010; ++expected) {
    const SecocReading reading = receiver16.verify(secoc_protect(sender16, secoc_data(3)));
    ASSERT_EQ(reading.status, SecocStatus::authentic) << "freshness " << expected;
    EXPECT_EQ(reading.freshness, expected);
  }
}

TEST(SecocFreshness, AcceptsUpToOneEpochOfLostFrames) {
  const SecocParameters p = secoc_params(24, 8);
  SecocSender sender = secoc_sender(p, 0);
  SecocReceiver receiver = secoc_receiver(p, 0);
  const SecocBytes data = secoc_data(4);
  const auto lose = [&](int frames) {
    for (int i = 0; i < frames; ++i) ASSERT_FALSE(secoc_protect(sender, data).empty());
  };
  EXPECT_EQ(receiver.verify(secoc_protect(sender, data)).freshness, 1u);
  lose(199);
  EXPECT_EQ(receiver.verify(secoc_protect(sender, data)).freshness, 201u);
  lose(255);  // 2^8 - 1 lost: the most one epoch allows
  SecocReading reading = receiver.verify(secoc_protect(sender, data));
  EXPECT_EQ(reading.status, SecocStatus::authentic);
  EXPECT_EQ(reading.freshness, 457u);
  lose(256);  // one more: the epoch cannot be told any more
  reading = receiver.verify(secoc_protect(sender, data));
  EXPECT_EQ(reading.status, SecocStatus::unauthenticated);
  EXPECT_EQ(receiver.freshness(), 457u);
}

TEST(SecocFreshness, WithoutFreshnessInTheFrameAcceptsTheWindowsLostFrames) {
  const SecocParameters p = secoc_params(64, 0);  // freshness_window 4: last+1 .. last+4
  SecocSender sender = secoc_sender(p, 100);
  SecocReceiver receiver = secoc_receiver(p, 100);
  const SecocBytes data = secoc_data(8);
  EXPECT_EQ(receiver.verify(secoc_protect(sender, data)).freshness, 101u);
  for (int i = 0; i < 3; ++i) (void)secoc_protect(sender, data);
  SecocReading reading = receiver.verify(secoc_protect(sender, data));
  EXPECT_EQ(reading.status, SecocStatus::authentic);
  EXPECT_EQ(reading.freshness, 105u);
  for (int i = 0; i < 4; ++i) (void)secoc_protect(sender, data);
  EXPECT_EQ(receiver.verify(secoc_protect(sender, data)).status, SecocStatus::unauthenticated);
  EXPECT_EQ(receiver.freshness(), 105u);
}

TEST(SecocFreshness, AFrameSentAgainIsReplayed) {
  for (const auto& [mac_bits, fresh_bits] :
       std::vector<std::pair<unsigned, unsigned>>{{24, 8}, {32, 16}, {128, 64}, {64, 0}}) {
    const SecocParameters p = secoc_params(mac_bits, fresh_bits);
    SecocSender sender = secoc_sender(p, 250);
    SecocReceiver receiver = secoc_receiver(p, 250);
    std::vector<SecocBytes> sent;
    for (int i = 0; i < 10; ++i) {
      sent.push_back(secoc_protect(sender, secoc_data(5, static_cast<unsigned>(i))));
      ASSERT_EQ(receiver.verify(sent.back()).status, SecocStatus::authentic);
    }
    // 251..260: the last one again, and (within the window without freshness) the fourth last.
    for (const std::size_t index : {std::size_t{9}, std::size_t{6}}) {
      const SecocReading reading = receiver.verify(sent[index]);
      EXPECT_EQ(reading.status, SecocStatus::replayed) << mac_bits << "/" << fresh_bits << ", frame " << index;
      EXPECT_EQ(reading.freshness, 251 + index);
      EXPECT_EQ(reading.authentic_size, 5u);
      EXPECT_EQ(receiver.freshness(), 260u);
    }
    if (fresh_bits != 0) {  // before the epoch boundary at 256, read at 260
      EXPECT_EQ(receiver.verify(sent[1]).status, SecocStatus::replayed) << mac_bits << "/" << fresh_bits;
    }
    EXPECT_EQ(receiver.verify(secoc_protect(sender, secoc_data(5))).status, SecocStatus::authentic);
  }
}

TEST(SecocFreshness, AReplayOlderThanOneEpochIsUnauthenticated) {
  const SecocParameters p = secoc_params(24, 8);
  SecocSender sender = secoc_sender(p, 0);
  SecocReceiver receiver = secoc_receiver(p, 0);
  const SecocBytes old = secoc_protect(sender, secoc_data(4));
  ASSERT_EQ(receiver.verify(old).status, SecocStatus::authentic);
  for (int i = 0; i < 300; ++i)
    ASSERT_EQ(receiver.verify(secoc_protect(sender, secoc_data(4))).status, SecocStatus::authentic);
  EXPECT_EQ(receiver.verify(old).status, SecocStatus::unauthenticated);
}

TEST(SecocRefusal, AnyFlippedBitIsUnauthenticated) {
  for (const auto& [mac_bits, fresh_bits] : std::vector<std::pair<unsigned, unsigned>>{{24, 8}, {128, 64}, {64, 0}}) {
    const SecocParameters p = secoc_params(mac_bits, fresh_bits);
    SecocSender sender = secoc_sender(p, 254);
    SecocReceiver receiver = secoc_receiver(p, 254);
    const SecocBytes pdu = secoc_protect(sender, secoc_data(8));
    for (std::size_t bit = 0; bit < pdu.size() * 8; ++bit) {
      SecocBytes flipped = pdu;
      flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
      EXPECT_EQ(receiver.verify(flipped).status, SecocStatus::unauthenticated)
          << mac_bits << "/" << fresh_bits << ", bit " << bit;
    }
    EXPECT_EQ(receiver.freshness(), 254u);
    EXPECT_EQ(receiver.verify(pdu).status, SecocStatus::authentic);
  }
}

TEST(SecocRefusal, AnotherKeyOrDataIdIsUnauthenticated) {
  const SecocParameters p = secoc_params(24, 8, 0x123);
  SecocSender sender = secoc_sender(p, 10);
  SecocReceiver other_key = secoc_receiver(p, 10, "00112233445566778899aabbccddeefe");
  SecocReceiver other_id = secoc_receiver(secoc_params(24, 8, 0x124), 10);
  SecocReceiver other_high_byte = secoc_receiver(secoc_params(24, 8, 0x01000123), 10);
  SecocReceiver right = secoc_receiver(p, 10);
  for (int i = 0; i < 5; ++i) {
    const SecocBytes pdu = secoc_protect(sender, secoc_data(6, static_cast<unsigned>(i)));
    EXPECT_EQ(other_key.verify(pdu).status, SecocStatus::unauthenticated);
    EXPECT_EQ(other_id.verify(pdu).status, SecocStatus::unauthenticated);
    EXPECT_EQ(other_high_byte.verify(pdu).status, SecocStatus::unauthenticated);
    EXPECT_EQ(right.verify(pdu).status, SecocStatus::authentic);
  }
  EXPECT_EQ(other_key.freshness(), 10u);
}

TEST(SecocRefusal, FramesShorterThanTheOverheadAreUnauthenticated) {
  const SecocParameters p = secoc_params(24, 8);
  SecocReceiver receiver = secoc_receiver(p, 0);
  SecocSender sender = secoc_sender(p, 0);
  const SecocBytes pdu = secoc_protect(sender, {});
  ASSERT_EQ(pdu.size(), 4u);
  for (std::size_t size = 0; size < pdu.size(); ++size) {
    const SecocReading reading = receiver.verify(std::span(pdu).first(size));
    EXPECT_EQ(reading.status, SecocStatus::unauthenticated) << size << " bytes";
    EXPECT_EQ(reading.authentic_size, 0u);
  }
  const SecocBytes longer = secoc_protect(sender, secoc_data(5));
  EXPECT_EQ(receiver.verify(std::span(longer).first(longer.size() - 1)).status, SecocStatus::unauthenticated);
  EXPECT_EQ(receiver.verify(pdu).status, SecocStatus::authentic);
}

TEST(SecocRefusal, MakeRefusesBadParametersWithTheReason) {
  const SecocBytes key = secoc_hex(kSecocKeyHex);
  const std::vector<std::pair<SecocParameters, std::string>> bad = {
      {{1, 0, 8, 4}, "SecOC mac_bits 0 is not valid: 8 to 128, a multiple of 8"},
      {{1, 12, 8, 4}, "SecOC mac_bits 12 is not valid: 8 to 128, a multiple of 8"},
      {{1, 136, 8, 4}, "SecOC mac_bits 136 is not valid: 8 to 128, a multiple of 8"},
      {{1, 24, 4, 4}, "SecOC freshness_bits 4 is not valid: 0 to 64, a multiple of 8"},
      {{1, 24, 72, 4}, "SecOC freshness_bits 72 is not valid: 0 to 64, a multiple of 8"},
      {{1, 24, 0, 0}, "SecOC freshness_window 0 is not valid: 1 to 16"},
      {{1, 24, 0, 17}, "SecOC freshness_window 17 is not valid: 1 to 16"}};
  for (const auto& [params, reason] : bad) {
    const Result<void> checked = check_secoc_parameters(params);
    ASSERT_FALSE(checked);
    EXPECT_EQ(checked.error().text, reason);
    const Result<SecocSender> sender = SecocSender::make(key, params, 0);
    ASSERT_FALSE(sender);
    EXPECT_EQ(sender.error().text, reason);
    const Result<SecocReceiver> receiver = SecocReceiver::make(key, params, 0);
    ASSERT_FALSE(receiver);
    EXPECT_EQ(receiver.error().text, reason);
  }
  for (const std::size_t size : {std::size_t{0}, std::size_t{15}, std::size_t{32}}) {
    const Result<SecocSender> sender = SecocSender::make(SecocBytes(size, 1), secoc_params(24, 8), 0);
    ASSERT_FALSE(sender);
    EXPECT_EQ(sender.error().text, "a SecOC key has 16 bytes (AES-128), this one " + std::to_string(size));
    EXPECT_FALSE(SecocReceiver::make(SecocBytes(size, 1), secoc_params(24, 8), 0));
  }
  EXPECT_TRUE(check_secoc_parameters({1, 8, 0, 1}));
  EXPECT_TRUE(check_secoc_parameters({1, 128, 64, 16}));
}

TEST(SecocRefusal, TheCounterNeverWraps) {
  const SecocParameters p = secoc_params(24, 8);
  SecocSender sender = secoc_sender(p, kSecocMax - 1);
  SecocReceiver receiver = secoc_receiver(p, kSecocMax - 1);
  const SecocBytes last = secoc_protect(sender, secoc_data(4));
  ASSERT_FALSE(last.empty());
  EXPECT_EQ(sender.freshness(), kSecocMax);
  EXPECT_EQ(receiver.verify(last).freshness, kSecocMax);
  SecocBytes out(64);
  EXPECT_EQ(sender.protect(secoc_data(4), out), 0u) << "the sender at UINT64_MAX refuses";
  EXPECT_EQ(sender.freshness(), kSecocMax);

  // A receiver near the end never takes a value past UINT64_MAX for one that wrapped to 0, 1, ...
  for (const auto& [mac_bits, fresh_bits] : std::vector<std::pair<unsigned, unsigned>>{{24, 8}, {32, 16}, {64, 0}}) {
    const SecocParameters q = secoc_params(mac_bits, fresh_bits);
    SecocReceiver near_end = secoc_receiver(q, kSecocMax - 2);
    SecocSender wrapped = secoc_sender(q, 0);  // its first frame carries 1 == kSecocMax + 2 modulo 2^64
    const SecocReading reading = near_end.verify(secoc_protect(wrapped, secoc_data(4)));
    EXPECT_NE(reading.status, SecocStatus::authentic) << mac_bits << "/" << fresh_bits;
    EXPECT_EQ(near_end.freshness(), kSecocMax - 2);
  }
  SecocReceiver at_end = secoc_receiver(secoc_params(64, 0), kSecocMax);
  SecocSender sender_of_max = secoc_sender(secoc_params(64, 0), kSecocMax - 1);
  EXPECT_EQ(at_end.verify(secoc_protect(sender_of_max, secoc_data(4))).status, SecocStatus::replayed);
  EXPECT_STREQ(to_string(SecocStatus::replayed), "replayed");
}

}  // namespace
}  // namespace cosmic

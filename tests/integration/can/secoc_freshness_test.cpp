// The CAN adapter's SecOC state (secoc_streams.hpp, secoc_freshness.hpp), without a CAN bus: what a
// sender protects verifies with the codec's receiver, on CAN FD padded to the payload; a sender
// uses only freshness values its store persisted and continues past them after a restart; a
// receiver restored from the file refuses the last frame it accepted; a broken file refuses SecOC
// rather than start counters from 0; forged senders never evict a sender that was heard.
#include <gtest/gtest.h>
#include <linux/can.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "secoc_freshness.hpp"
#include "secoc_streams.hpp"

namespace cosmic::can_detail {
namespace {

class QuietLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override { lines.emplace_back(message); }
  std::vector<std::string> lines;
};

SecocSpec spec_with(std::uint32_t freshness_bits = 8) {
  SecocSpec spec;
  spec.segment = "bus";
  spec.key =
      SecretKey({0x2b, 0x7e, 0x15, 0x16, 0x28, 0xae, 0xd2, 0xa6, 0xab, 0xf7, 0x15, 0x88, 0x09, 0xcf, 0x4f, 0x3c});
  spec.freshness_bits = freshness_bits;
  return spec;
}

SecocReceiver receiver_for(const SecocSpec& spec, std::uint32_t data_id, std::uint64_t last) {
  SecocParameters p;
  p.data_id = data_id;
  p.mac_bits = spec.mac_bits;
  p.freshness_bits = spec.freshness_bits;
  return SecocReceiver::make(spec.key.bytes(), p, last).value();
}

bool eventually(const std::function<bool()>& condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return condition();
}

class SecocFreshnessTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / ("secoc_freshness_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    file_ = (dir_ / "secoc-bus.json").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  nlohmann::json state() const {
    std::ifstream in(file_);
    return nlohmann::json::parse(in);
  }

  std::filesystem::path dir_;
  std::string file_;
  QuietLogger log_;
};

TEST_F(SecocFreshnessTest, WhatASenderProtectsVerifiesAndCanFdPadsTheDataToThePayload) {
  SecocFreshness store("", "bus: ", "fv:bus", log_);
  const SecocSpec spec = spec_with();
  auto tx = store.sender("wheel", spec, 0x123).value();
  std::array<std::uint8_t, 64> out{};
  const std::array<std::uint8_t, 2> data{0xA1, 0xA2};
  SecocReceiver receiver = receiver_for(spec, 0x123, 0);
  const std::size_t classic = tx->protect(data, 4, false, out);
  ASSERT_EQ(classic, 2u + 4u);
  const SecocReading first = receiver.verify(std::span<const std::uint8_t>(out.data(), classic));
  EXPECT_EQ(first.status, SecocStatus::authentic);
  EXPECT_EQ(first.authentic_size, 2u);
  const std::size_t fd = tx->protect(data, 4, true, out);
  ASSERT_EQ(fd, 4u + 4u);
  EXPECT_EQ(out[2], 0);
  EXPECT_EQ(out[3], 0);
  EXPECT_EQ(receiver.verify(std::span<const std::uint8_t>(out.data(), fd)).authentic_size, 4u);
  EXPECT_EQ(tx->last_used(), 2u);
  // The same through the adapter's receiving state, which cuts an FD frame's padding off.
  auto rx = store.receiver("wheel", spec, false).value();
  std::array<std::uint8_t, 12> frame{};  // the DLC's 12 bytes: PDU of 8, then padding
  const std::size_t third = tx->protect(data, 4, true, frame);
  ASSERT_EQ(third, 8u);
  const SecocCheck check = rx->verify(0x123, frame, 4, true);
  ASSERT_EQ(check.status, SecocStatus::authentic);
  EXPECT_EQ(check.data.size(), 4u);
  EXPECT_EQ(rx->verify(0x123, frame, 4, true).status, SecocStatus::replayed);
}

TEST_F(SecocFreshnessTest, ASenderUsesOnlyPersistedValuesAndARestartContinuesPastThem) {
  const SecocSpec spec = spec_with();  // 8 bits: leases of 128
  std::uint64_t lease = 0;
  {
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    auto tx = store.sender("wheel", spec, 0x77).value();
    std::array<std::uint8_t, 8> out{};
    const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
    EXPECT_EQ(tx->protect(data, 4, false, out), 0u) << "nothing is persisted yet: no value may be used";
    store.persist_now();
    EXPECT_EQ(state()["senders"]["wheel/119"], 128u);
    for (int i = 0; i < 100; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u) << i;
    // Past half the lease: the lane poked the store's thread, which persisted a further one.
    store.poke();
    ASSERT_TRUE(eventually([&] { return tx->lease() > 128; })) << tx->lease();
    EXPECT_EQ(tx->lease(), 100u + 128u);
    EXPECT_EQ(state()["senders"]["wheel/119"], 228u);
    for (int i = 0; i < 10; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
    store.stop();
    lease = state()["senders"]["wheel/119"].get<std::uint64_t>();
    EXPECT_GE(lease, 110u);
  }
  SecocFreshness again(file_, "bus: ", "fv:bus", log_);
  auto tx = again.sender("wheel", spec, 0x77).value();
  again.persist_now();
  std::array<std::uint8_t, 8> out{};
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  // The first value after the restart is lease + 1: past everything used, within an epoch.
  SecocReceiver receiver = receiver_for(spec, 0x77, 110);
  const SecocReading reading = receiver.verify(out);
  EXPECT_EQ(reading.status, SecocStatus::authentic);
  EXPECT_EQ(reading.freshness, lease + 1);
}

TEST_F(SecocFreshnessTest, ARestoredReceiverRefusesTheLastFrameItAccepted) {
  const SecocSpec spec = spec_with();
  SecocFreshness sending("", "bus: ", "fv:bus", log_);
  auto tx = sending.sender("wheel", spec, 0x123).value();
  std::array<std::uint8_t, 8> frame{};
  const std::array<std::uint8_t, 4> data{9, 8, 7, 6};
  {
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    auto rx = store.receiver("wheel", spec, false).value();
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(tx->protect(data, 4, false, frame), 8u);
      ASSERT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::authentic);
    }
    store.persist_now();
    store.stop();
  }
  EXPECT_EQ(state()["receivers"]["wheel/291"], 3u);
  SecocFreshness again(file_, "bus: ", "fv:bus", log_);
  auto rx = again.receiver("wheel", spec, false).value();
  EXPECT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::replayed);
  ASSERT_EQ(tx->protect(data, 4, false, frame), 8u);
  EXPECT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::authentic);
}

TEST_F(SecocFreshnessTest, ABrokenFileRefusesSecocAndIsLeftAsItIs) {
  std::ofstream(file_) << "{\"version\": 1, \"senders\": {\"wheel/119\": -5}}";
  SecocFreshness store(file_, "bus: ", "fv:bus", log_);
  const auto tx = store.sender("wheel", spec_with(), 0x77);
  ASSERT_FALSE(tx);
  EXPECT_NE(tx.error().text.find("is not an unsigned number"), std::string::npos) << tx.error().text;
  EXPECT_FALSE(store.receiver("wheel", spec_with(), false));
  store.persist_now();
  store.stop();
  std::ifstream in(file_);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "{\"version\": 1, \"senders\": {\"wheel/119\": -5}}");
}

TEST_F(SecocFreshnessTest, AChangedKeyKeepsTheCounterGoing) {
  SecocFreshness store("", "bus: ", "fv:bus", log_);
  SecocSpec spec = spec_with();
  auto tx = store.sender("wheel", spec, 0x77).value();
  std::array<std::uint8_t, 8> out{};
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  for (int i = 0; i < 5; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  EXPECT_EQ(store.sender("wheel", spec, 0x77).value(), tx) << "unchanged: the same state";
  spec.key = SecretKey(std::vector<std::uint8_t>(16, 0x42));
  auto changed = store.sender("wheel", spec, 0x77).value();
  EXPECT_NE(changed, tx);
  EXPECT_EQ(changed->last_used(), 5u);
}

TEST_F(SecocFreshnessTest, ForgedSendersNeverEvictOneThatWasHeard) {
  const SecocSpec spec = spec_with();
  SecocFreshness store("", "bus: ", "fv:bus", log_);
  auto rx = store.receiver("brake", spec, true).value();
  auto heard = store.sender("brake", spec, secoc_data_id(spec, 0x0C01E064 | CAN_EFF_FLAG, true)).value();
  std::array<std::uint8_t, 8> frame{};
  const std::array<std::uint8_t, 4> data{1, 1, 1, 1};
  ASSERT_EQ(heard->protect(data, 4, false, frame), 8u);
  ASSERT_EQ(rx->verify(0x0C01E064 | CAN_EFF_FLAG, frame, 4, false).status, SecocStatus::authentic);
  // 200 other TxNodes (with the same etag) send forgeries: more than the table holds.
  const std::array<std::uint8_t, 8> forged{1, 1, 1, 1, 2, 0, 0, 0};
  for (std::uint32_t node = 0; node < 200; ++node) {
    const canid_t id = (0x30u << 21) | ((node & 0x7F) << 14) | (0x64 + (node >> 7)) | CAN_EFF_FLAG;
    EXPECT_EQ(rx->verify(id, forged, 4, false).status, SecocStatus::unauthenticated);
  }
  ASSERT_EQ(heard->protect(data, 4, false, frame), 8u);
  EXPECT_EQ(rx->verify(0x0C01E064 | CAN_EFF_FLAG, frame, 4, false).status, SecocStatus::authentic);
  EXPECT_EQ(rx->snapshot().size(), 1u);
}

TEST(SecocDataId, TheLayoutLeavesThePriorityOutANativeIdentifierIsWhole) {
  SecocSpec spec = spec_with();
  EXPECT_EQ(secoc_data_id(spec, (0x30u << 21) | (3u << 14) | 0x3FFE | CAN_EFF_FLAG, true), (3u << 14) | 0x3FFE);
  EXPECT_EQ(secoc_data_id(spec, 0x18FF0001 | CAN_EFF_FLAG, false), 0x18FF0001u);
  EXPECT_EQ(secoc_data_id(spec, 0x123, false), 0x123u);
  spec.data_id = 0x77;
  EXPECT_EQ(secoc_data_id(spec, 0x123, false), 0x77u);
  EXPECT_EQ(secoc_lease_step(8), 128u);
  EXPECT_EQ(secoc_lease_step(16), 32768u);
  EXPECT_EQ(secoc_lease_step(64), 65536u);
}

}  // namespace
}  // namespace cosmic::can_detail

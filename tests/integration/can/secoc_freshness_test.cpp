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

// The sender's freshness value `fresh` as a receiver that accepted `last` reads it (0: not authentic).
std::uint64_t read_by(const SecocSpec& spec, std::uint32_t data_id, std::uint64_t last,
                      std::span<const std::uint8_t> frame) {
  SecocReceiver receiver = receiver_for(spec, data_id, last);
  const SecocReading reading = receiver.verify(frame);
  return reading.status == SecocStatus::authentic ? reading.freshness : 0;
}

TEST_F(SecocFreshnessTest, ASenderUsesOnlyPersistedValuesAndACleanRestartContinuesWhereItStopped) {
  const SecocSpec spec = spec_with();  // 8 bits: leases of 128, a start's first lease 8
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  std::array<std::uint8_t, 8> out{};
  {
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    store.attach();
    auto tx = store.sender("wheel", spec, 0x77).value();
    EXPECT_EQ(tx->protect(data, 4, false, out), 0u) << "nothing is persisted yet: no value may be used";
    ASSERT_TRUE(store.persist_now());
    EXPECT_EQ(state()["senders"]["wheel/119"], 8u);
    for (int i = 0; i < 8; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u) << i;
    // The lane poked the store's thread at the first frame: a whole step beyond the last value used.
    ASSERT_TRUE(eventually([&] { return tx->lease() > 8; })) << tx->lease();
    EXPECT_GE(tx->lease(), 1u + 128u);
    for (int i = 0; i < 100; ++i) {
      ASSERT_TRUE(eventually([&] { return tx->protect(data, 4, false, out) == 8u; })) << i;
      store.poke();
    }
    EXPECT_EQ(tx->last_used(), 108u);
    EXPECT_GT(state()["senders"]["wheel/119"].get<std::uint64_t>(), 108u);
    store.detach();  // a clean stop: the lease is cut back to the last value used
    EXPECT_EQ(state()["senders"]["wheel/119"], 108u);
    EXPECT_EQ(tx->protect(data, 4, false, out), 0u) << "a retired sender sends nothing";
  }
  SecocFreshness again(file_, "bus: ", "fv:bus", log_);
  again.attach();
  auto tx = again.sender("wheel", spec, 0x77).value();
  ASSERT_TRUE(again.persist_now());
  ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  EXPECT_EQ(read_by(spec, 0x77, 108, out), 109u) << "a clean restart skips nothing";
  again.detach();
}

TEST_F(SecocFreshnessTest, CrashesWithoutFramesInBetweenStayWithinAReceiversReach) {
  const SecocSpec spec = spec_with();
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  std::array<std::uint8_t, 8> out{};
  {
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    auto tx = store.sender("wheel", spec, 0x77).value();
    ASSERT_TRUE(store.persist_now());
    for (int i = 0; i < 3; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
    store.poke();
    ASSERT_TRUE(eventually([&] { return tx->lease() > 8; }));
  }                                           // a crash: no detach, the lease stays as persisted (3 + 128)
  for (int start = 0; start < 10; ++start) {  // ten crashes in a row, no frame sent in between
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    (void)store.sender("wheel", spec, 0x77).value();
    ASSERT_TRUE(store.persist_now());
  }
  SecocFreshness last(file_, "bus: ", "fv:bus", log_);
  auto tx = last.sender("wheel", spec, 0x77).value();
  ASSERT_TRUE(last.persist_now());
  ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  // The lease 131 after the first crash, 8 more for each of the ten starts that sent nothing: the
  // next start sends 212, within the 255 a receiver that last took 3 can follow.
  EXPECT_EQ(read_by(spec, 0x77, 3, out), 3u + 128u + 10u * 8u + 1u);
}

TEST_F(SecocFreshnessTest, ARestoredReceiverRefusesTheLastFrameItAccepted) {
  const SecocSpec spec = spec_with();
  SecocFreshness sending("", "bus: ", "fv:bus", log_);
  auto tx = sending.sender("wheel", spec, 0x123).value();
  std::array<std::uint8_t, 8> frame{};
  const std::array<std::uint8_t, 4> data{9, 8, 7, 6};
  {
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    store.attach();
    auto rx = store.receiver("wheel", spec, false).value();
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(tx->protect(data, 4, false, frame), 8u);
      ASSERT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::authentic);
    }
    store.detach();
  }
  EXPECT_EQ(state()["receivers"]["wheel/291"], 3u);
  SecocFreshness again(file_, "bus: ", "fv:bus", log_);
  auto rx = again.receiver("wheel", spec, false).value();
  EXPECT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::replayed);
  ASSERT_EQ(tx->protect(data, 4, false, frame), 8u);
  EXPECT_EQ(rx->verify(0x123, frame, 4, false).status, SecocStatus::authentic);
}

TEST_F(SecocFreshnessTest, ABrokenFileRefusesSecocAndIsLeftAsItIs) {
  for (const std::string broken : {"{\"version\": 1, \"senders\": {\"wheel/119\": -5}}", "{\"version\": \"1\"}", "[1]",
                                   "{\"version\": 1, \"receivers\": 7}", "not json"}) {
    std::ofstream(file_) << broken;
    SecocFreshness store(file_, "bus: ", "fv:bus", log_);
    store.attach();
    const auto tx = store.sender("wheel", spec_with(), 0x77);
    ASSERT_FALSE(tx) << broken;
    EXPECT_NE(tx.error().text.find("SecOC is refused on this segment"), std::string::npos) << tx.error().text;
    EXPECT_FALSE(store.receiver("wheel", spec_with(), false));
    store.persist_now();
    store.detach();
    std::ifstream in(file_);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), broken);
  }
}

TEST_F(SecocFreshnessTest, AChangedKeyRetiresTheOldSenderAndTheNewOneContinues) {
  SecocFreshness store("", "bus: ", "fv:bus", log_);
  SecocSpec spec = spec_with();
  auto tx = store.sender("wheel", spec, 0x77).value();
  std::array<std::uint8_t, 8> out{};
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  for (int i = 0; i < 5; ++i) ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  spec.cost = std::chrono::microseconds(30);
  spec.key_file = "/elsewhere/the-same.key";
  EXPECT_EQ(store.sender("wheel", spec, 0x77).value(), tx) << "the same MACs: the same state";
  spec.key = SecretKey(std::vector<std::uint8_t>(16, 0x42));
  auto changed = store.sender("wheel", spec, 0x77).value();
  EXPECT_NE(changed, tx);
  EXPECT_EQ(changed->last_used(), 5u);
  EXPECT_EQ(tx->protect(data, 4, false, out), 0u) << "the old state never sends a value the new one will";
  ASSERT_EQ(changed->protect(data, 4, false, out), 8u);
  EXPECT_EQ(read_by(spec, 0x77, 5, out), 6u);
}

TEST_F(SecocFreshnessTest, AdaptersThatShareTheStoreRetireItsSendersOnlyWhenTheLastLeaves) {
  const SecocSpec spec = spec_with();
  SecocFreshness store(file_, "bus: ", "fv:bus", log_);
  store.attach();  // the adapter of the running configuration
  store.attach();  // its replacement, made by a reload
  auto tx = store.sender("wheel", spec, 0x77).value();
  ASSERT_TRUE(store.persist_now());
  std::array<std::uint8_t, 8> out{};
  const std::array<std::uint8_t, 4> data{1, 2, 3, 4};
  ASSERT_EQ(tx->protect(data, 4, false, out), 8u);
  store.detach();  // the old adapter stops: the replacement still sends
  EXPECT_EQ(tx->protect(data, 4, false, out), 8u);
  store.detach();
  EXPECT_EQ(state()["senders"]["wheel/119"], 2u);
}

TEST_F(SecocFreshnessTest, WithAGivenDataIdEachSenderKeepsItsOwnFreshness) {
  SecocSpec spec = spec_with();
  spec.data_id = 0x1234;
  SecocFreshness store("", "bus: ", "fv:bus", log_);
  auto rx = store.receiver("brake", spec, true).value();
  SecocFreshness node_a("", "a: ", "fv:a", log_);
  SecocFreshness node_b("", "b: ", "fv:b", log_);
  auto a = node_a.sender("brake", spec, 0x1234).value();
  auto b = node_b.sender("brake", spec, 0x1234).value();
  const canid_t from_a = (0x30u << 21) | (1u << 14) | 0x64 | CAN_EFF_FLAG;
  const canid_t from_b = (0x30u << 21) | (2u << 14) | 0x64 | CAN_EFF_FLAG;
  std::array<std::uint8_t, 8> frame{};
  const std::array<std::uint8_t, 4> data{5, 5, 5, 5};
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(a->protect(data, 4, false, frame), 8u);
    ASSERT_EQ(rx->verify(from_a, frame, 4, false).status, SecocStatus::authentic) << i;
  }
  ASSERT_EQ(b->protect(data, 4, false, frame), 8u);  // node b's first frame: freshness 1
  EXPECT_EQ(rx->verify(from_b, frame, 4, false).status, SecocStatus::authentic);
  EXPECT_EQ(rx->snapshot().size(), 2u);
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
  EXPECT_EQ(secoc_start_step(8), 8u);
  EXPECT_EQ(secoc_source((0x30u << 21) | (3u << 14) | 0x3FFE | CAN_EFF_FLAG, true), (3u << 14) | 0x3FFE);
}

}  // namespace
}  // namespace cosmic::can_detail

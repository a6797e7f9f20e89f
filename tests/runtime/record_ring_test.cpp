// The recorder's many-to-one queue (cosmic/record_ring.hpp): records come out whole and in order,
// across the end of the buffer; a full ring refuses without waiting and takes records again once
// read, and a long read gives room back while it takes; records longer than a quarter of it are
// refused; and producers on several threads lose nothing that was accepted and never interleave
// two records (here for ThreadSanitizer too).
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <map>
#include <thread>
#include <vector>

#include "cosmic/record_ring.hpp"

namespace cosmic {
namespace {

// A record of `size` bytes: its writer and number, then a pattern that depends on both.
std::vector<std::uint8_t> record_of(std::uint32_t writer, std::uint32_t number, std::size_t size) {
  std::vector<std::uint8_t> bytes(std::max<std::size_t>(size, 8));
  std::memcpy(bytes.data(), &writer, 4);
  std::memcpy(bytes.data() + 4, &number, 4);
  for (std::size_t i = 8; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(writer * 31 + number + i);
  return bytes;
}

bool write(RecordRing& ring, const std::vector<std::uint8_t>& bytes) {
  const std::span<const std::uint8_t> parts[] = {{bytes.data(), 3}, {bytes.data() + 3, bytes.size() - 3}};
  return ring.try_write(parts);
}

std::vector<std::vector<std::uint8_t>> read_all(RecordRing& ring) {
  std::vector<std::vector<std::uint8_t>> out;
  while (ring.read([&](std::span<const std::uint8_t> r) { out.emplace_back(r.begin(), r.end()); }, 16) > 0) {
  }
  return out;
}

TEST(RecordRing, CapacityIsAPowerOfTwoOfAtLeastTheMinimum) {
  EXPECT_EQ(RecordRing(100).capacity(), RecordRing::kMinCapacity);
  EXPECT_EQ(RecordRing(10000).capacity(), 8192u);
  EXPECT_EQ(RecordRing(8192).max_record(), 2048u - 8);
}

TEST(RecordRing, RecordsComeOutWholeInOrderAcrossTheEnd) {
  RecordRing ring(4096);
  std::uint32_t written = 0;
  std::uint32_t read = 0;
  // Sizes that do not divide the capacity: records wrap with padding many times.
  for (int round = 0; round < 200; ++round) {
    for (int i = 0; i < 3; ++i) {
      const auto bytes = record_of(1, written, 37 + (written * 53) % 500);
      ASSERT_TRUE(write(ring, bytes)) << written;
      ++written;
    }
    for (const auto& record : read_all(ring)) {
      EXPECT_EQ(record, record_of(1, read, 37 + (read * 53) % 500)) << read;
      ++read;
    }
  }
  EXPECT_EQ(read, written);
  EXPECT_EQ(ring.used(), 0u);
}

TEST(RecordRing, AFullRingRefusesAndTakesRecordsAgainOnceRead) {
  RecordRing ring(4096);
  std::uint32_t accepted = 0;
  while (write(ring, record_of(2, accepted, 200))) ++accepted;
  // 208 bytes each with the header, 4096 in all.
  EXPECT_EQ(accepted, 4096u / 208);
  EXPECT_FALSE(write(ring, record_of(2, accepted, 200)));
  const auto first = [&] {
    std::vector<std::uint8_t> out;
    ring.read([&](std::span<const std::uint8_t> r) { out.assign(r.begin(), r.end()); }, 1);
    return out;
  }();
  EXPECT_EQ(first, record_of(2, 0, 200));
  EXPECT_TRUE(write(ring, record_of(2, 99, 200))) << "the room read is free again";
}

// The room of what one read() took goes back to the producers in pieces of an eighth of the ring,
// not only when read() returns: a take that waits (the writer's slow write) holds back little.
TEST(RecordRing, ALongReadGivesBackRoomWhileItTakes) {
  RecordRing ring(4096);
  std::uint32_t accepted = 0;
  while (write(ring, record_of(3, accepted, 200))) ++accepted;
  std::uint32_t taken = 0;
  bool refilled = false;
  ring.read(
      [&](std::span<const std::uint8_t>) {
        // By the fifth record the first three (624 bytes, over an eighth) are free again.
        if (++taken == 5) refilled = write(ring, record_of(3, 99, 200));
      },
      accepted);
  EXPECT_TRUE(refilled);
  EXPECT_EQ(taken, accepted);
}

TEST(RecordRing, ARecordLongerThanAQuarterIsRefused) {
  RecordRing ring(4096);
  EXPECT_TRUE(write(ring, record_of(3, 0, ring.max_record())));
  EXPECT_FALSE(write(ring, record_of(3, 1, ring.max_record() + 1)));
  EXPECT_EQ(read_all(ring).size(), 1u);
}

TEST(RecordRing, ConcurrentProducersLoseNothingAcceptedAndNeverInterleave) {
  RecordRing ring(1 << 16);
  constexpr std::uint32_t kWriters = 4;
  constexpr std::uint32_t kEach = 20000;
  std::atomic<std::uint32_t> running{kWriters};
  std::vector<std::uint32_t> accepted(kWriters, 0);
  std::vector<std::thread> writers;
  for (std::uint32_t w = 0; w < kWriters; ++w) {
    writers.emplace_back([&, w] {
      for (std::uint32_t n = 0; n < kEach; ++n) {
        // Each writer numbers only what the ring accepted, so the reader can check order and gaps.
        if (write(ring, record_of(w, accepted[w], 16 + (n * 7 + w * 13) % 300))) ++accepted[w];
      }
      running.fetch_sub(1);
    });
  }
  std::map<std::uint32_t, std::uint32_t> next;  // per writer: the number expected next
  std::uint64_t taken = 0;
  bool whole = true;
  const auto take = [&](std::span<const std::uint8_t> r) {
    std::uint32_t writer = 0, number = 0;
    std::memcpy(&writer, r.data(), 4);
    std::memcpy(&number, r.data() + 4, 4);
    const std::vector<std::uint8_t> bytes(r.begin(), r.end());
    whole = whole && bytes == record_of(writer, number, bytes.size()) && number == next[writer];
    ++next[writer];
    ++taken;
  };
  while (running.load() > 0) ring.read(take, 256);
  for (auto& t : writers) t.join();
  while (ring.read(take, 256) > 0) {
  }
  EXPECT_TRUE(whole) << "a record came out damaged or out of its writer's order";
  std::uint64_t sum = 0;
  for (std::uint32_t w = 0; w < kWriters; ++w) {
    EXPECT_EQ(next[w], accepted[w]) << "writer " << w;
    sum += accepted[w];
  }
  EXPECT_EQ(taken, sum);
  EXPECT_GT(sum, 0u);
}

}  // namespace
}  // namespace cosmic

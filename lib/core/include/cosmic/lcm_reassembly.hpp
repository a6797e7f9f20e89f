// Reassembly of LCM's fragmented messages (cosmic/lcm_udpm.hpp) with bounded memory. Pure, no
// I/O; owned and called by one thread (the LCM adapter's receive thread).
//
// A sender (its IPv4 address and UDP port) has at most one message in reassembly, as liblcm
// sends the fragments of one message back to back: a fragment of another sequence from the same
// sender abandons the one before. Messages whose size exceeds the limit given at construction are
// refused at their first fragment; the bytes held for all senders together stay within
// max(kMinBudget, 2 x that limit), the least recently touched message giving way first, and at
// most kMaxSenders messages are held. A duplicate fragment, or one that disagrees with the
// message's size or count, is refused without disturbing the message; so is a late fragment of
// one of the last kMaxSenders messages completed. The budget counts each message's bookkeeping
// (a flag and a slice per fragment) too; bytes_held() reports the payload buffers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosmic/lcm_udpm.hpp"

namespace cosmic {

class LcmReassembler {
 public:
  static constexpr std::size_t kMaxSenders = 64;
  static constexpr std::size_t kMinBudget = 16u << 20;

  explicit LcmReassembler(std::size_t max_message_size);

  enum class Outcome {
    pending,   // kept; the message is not complete yet
    complete,  // the message is whole: see channel() and payload()
    refused,   // this fragment was not taken (too large, inconsistent, duplicate)
    ignored,   // a fragment of a message completed or skipped lately: nothing wrong, nothing kept
  };

  // One fragment (LcmDatagram::fragment set) from `sender`. After `complete`, channel() and
  // payload() show the message until the next call.
  Outcome add(std::uint64_t sender, const LcmDatagram& fragment);

  // The message `sequence` of `sender` is not wanted (its fragment 0 names a channel the caller
  // does not receive): what is held of it goes, and its further fragments are refused without
  // being held (nor counted as abandoned).
  void skip(std::uint64_t sender, std::uint32_t sequence);

  std::string_view channel() const { return completed_channel_; }
  std::span<const std::uint8_t> payload() const { return completed_; }

  // Messages given up before they were whole (abandoned for a newer one of their sender, or
  // evicted for room): each one lost to the receiver.
  std::uint64_t abandoned() const { return abandoned_; }
  std::size_t bytes_held() const { return bytes_held_; }
  std::size_t messages_held() const { return partials_.size(); }

 private:
  struct Partial {
    std::uint64_t sender = 0;
    std::uint32_t sequence = 0;
    std::uint16_t fragment_count = 0;
    std::uint16_t fragments_received = 0;
    std::uint64_t last_touch = 0;
    std::string channel;  // from fragment 0, once it came
    std::vector<std::uint8_t> data;
    std::vector<bool> received;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> slices;  // (offset, length) received
  };

  static std::size_t bookkeeping_of(std::uint16_t fragment_count);
  Partial* find_sender(std::uint64_t sender);
  Partial* start(std::uint64_t sender, const LcmDatagram& fragment);
  bool make_room(std::size_t bytes);
  void remember_finished(std::uint64_t sender, std::uint32_t sequence);
  void drop(std::size_t index);

  const std::size_t max_message_size_;
  const std::size_t budget_;
  std::vector<Partial> partials_;
  std::size_t bytes_held_ = 0;   // payload buffers
  std::size_t bookkeeping_ = 0;  // per-fragment flags and slices, counted in the budget too
  // The messages completed last (sender, sequence): a late duplicate of theirs is refused.
  std::array<std::pair<std::uint64_t, std::uint32_t>, kMaxSenders> finished_{};
  std::size_t next_finished_ = 0;
  std::size_t finished_count_ = 0;  // entries of finished_ in use
  std::uint64_t clock_ = 0;
  std::uint64_t abandoned_ = 0;
  std::string completed_channel_;
  std::vector<std::uint8_t> completed_;
};

}  // namespace cosmic

// LCM's UDP multicast datagrams as the LCM adapter's own transport receives them: each one through
// parse_lcm_datagram, the fragments into one LcmReassembler, many senders interleaved.
// Input: [limit: 3][plan payload size: 4][plan channel size: 1] then datagrams
// [length: 2][sender: 1][bytes].
// Checked beyond "no crash": a parsed datagram's channel and data lie inside it (the data ending
// where it ends), its channel has 1..63 bytes and no NUL, a fragment's slice lies inside its
// message and its number is below its count, and it serializes again to exactly its bytes; a
// short message is one a sender would send as one; the reassembler holds no more than its byte
// budget and kMaxSenders messages, leaves its state alone for a short message, refuses messages
// over its limit, and a completed message is within the limit, has a channel, and holds the
// completing fragment's slice where that fragment put it. plan_lcm_message agrees with a plan
// worked out as "fragment 0, then full fragments".
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>
#include <vector>

#include "cosmic/lcm_reassembly.hpp"
#include "cosmic/lcm_udpm.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

// [p, p + n) lies inside `whole` (compared as addresses: the pointers may belong to other objects).
bool inside(const void* p, std::size_t n, std::span<const std::uint8_t> whole) {
  const auto begin = reinterpret_cast<std::uintptr_t>(whole.data());
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  return at >= begin && at - begin <= whole.size() && n <= whole.size() - (at - begin);
}

bool valid_channel(std::string_view channel) {
  return !channel.empty() && channel.size() <= cosmic::kLcmMaxChannelBytes &&
         channel.find('\0') == std::string_view::npos;
}

// The datagram a sender would write for `d`.
std::vector<std::uint8_t> serialize(const cosmic::LcmDatagram& d) {
  std::vector<std::uint8_t> out;
  if (d.fragment) {
    const auto header =
        cosmic::lcm_fragment_header(d.sequence, d.message_size, d.fragment_offset, d.fragment_no, d.fragment_count);
    out.assign(header.begin(), header.end());
  } else {
    const auto header = cosmic::lcm_short_header(d.sequence);
    out.assign(header.begin(), header.end());
  }
  if (!d.fragment || d.fragment_no == 0) {
    out.insert(out.end(), d.channel.begin(), d.channel.end());
    out.push_back(0);
  }
  out.insert(out.end(), d.data.begin(), d.data.end());
  return out;
}

void check_datagram(const cosmic::LcmDatagram& d, std::span<const std::uint8_t> bytes) {
  require(bytes.size() <= cosmic::kLcmMaxDatagram);
  // The data is the rest of the datagram, a view into it.
  require(inside(d.data.data(), d.data.size(), bytes));
  require(d.data.data() + d.data.size() == bytes.data() + bytes.size());
  const bool has_channel = !d.fragment || d.fragment_no == 0;
  if (has_channel) {
    require(valid_channel(d.channel));
    require(inside(d.channel.data(), d.channel.size(), bytes));
    const std::size_t header = d.fragment ? cosmic::kLcmFragmentHeaderSize : cosmic::kLcmShortHeaderSize;
    require(reinterpret_cast<const std::uint8_t*>(d.channel.data()) == bytes.data() + header);
  } else {
    require(d.channel.empty());
  }
  if (d.fragment) {
    require(d.fragment_no < d.fragment_count);
    require(std::uint64_t{d.fragment_offset} + d.data.size() <= d.message_size);
    if (d.fragment_no == 0) require(d.fragment_offset == 0);
  } else {
    // What a receiver takes as a short message, a sender sends as one.
    const auto plan = cosmic::plan_lcm_message(d.channel.size(), d.data.size());
    require(plan.has_value() && plan->fragment_count == 0 && plan->first_slice == d.data.size());
  }
  // One encoding per datagram: nothing in it is ignored.
  const std::vector<std::uint8_t> again = serialize(d);
  require(again.size() == bytes.size());
  require(std::equal(again.begin(), again.end(), bytes.begin()));
}

void check_reassembly(cosmic::LcmReassembler& reassembler, std::size_t limit, std::uint64_t sender,
                      const cosmic::LcmDatagram& d) {
  const std::size_t bytes_before = reassembler.bytes_held();
  const std::size_t messages_before = reassembler.messages_held();
  const std::uint64_t abandoned_before = reassembler.abandoned();
  const auto outcome = reassembler.add(sender, d);
  using Outcome = cosmic::LcmReassembler::Outcome;

  require(reassembler.bytes_held() <= std::max(cosmic::LcmReassembler::kMinBudget, 2 * limit));
  require(reassembler.messages_held() <= cosmic::LcmReassembler::kMaxSenders);
  require(reassembler.messages_held() > 0 || reassembler.bytes_held() == 0);
  require(reassembler.abandoned() >= abandoned_before);
  if (!d.fragment) {
    // A short message is the adapter's to deliver: refused, and nothing held changes.
    require(outcome == Outcome::refused);
    require(reassembler.bytes_held() == bytes_before && reassembler.messages_held() == messages_before &&
            reassembler.abandoned() == abandoned_before);
    return;
  }
  // Too large: refused, or ignored as a fragment of a message that ended lately.
  if (d.message_size > limit) require(outcome == Outcome::refused || outcome == Outcome::ignored);
  if (outcome == Outcome::pending) require(reassembler.messages_held() > 0);
  if (outcome != Outcome::complete) return;

  const auto payload = reassembler.payload();
  require(payload.size() <= limit);
  require(payload.size() == d.message_size);
  require(valid_channel(reassembler.channel()));
  if (d.fragment_no == 0) require(reassembler.channel() == d.channel);
  // The slices tiled the message without overlap, so the last one is where it was written.
  require(d.data.empty() || std::memcmp(payload.data() + d.fragment_offset, d.data.data(), d.data.size()) == 0);
}

// plan_lcm_message against the same plan worked out another way: fragment 0 fills a datagram
// after channel and NUL, then as many full fragments as the rest needs.
void check_plan(std::size_t channel_size, std::size_t payload_size) {
  const auto plan = cosmic::plan_lcm_message(channel_size, payload_size);
  if (channel_size == 0 || channel_size > cosmic::kLcmMaxChannelBytes) {
    require(!plan);
    return;
  }
  if (channel_size + 1 + payload_size <= cosmic::kLcmShortMessageMax) {
    require(plan && plan->fragment_count == 0 && plan->first_slice == payload_size);
    return;
  }
  const std::size_t first = cosmic::kLcmFragmentMaxData - (channel_size + 1);
  require(payload_size > first);  // a message this long never fits in fragment 0
  const std::size_t rest = payload_size - first;
  const std::size_t count = 1 + (rest + cosmic::kLcmFragmentMaxData - 1) / cosmic::kLcmFragmentMaxData;
  if (count > 65535) {
    require(!plan);
    return;
  }
  require(plan && plan->fragment_count == count && plan->first_slice == first);
  require(cosmic::kLcmFragmentHeaderSize + channel_size + 1 + plan->first_slice <= cosmic::kLcmMaxDatagram);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  // Small limits (up to 1 MiB), so that messages are refused for size and the budget
  // (kMinBudget here) is reached by a few dozen senders. One read per statement: the operands
  // of | are evaluated in no set order, and an input must mean the same with every compiler.
  std::size_t limit = in.byte();
  limit = limit << 8 | in.byte();
  limit = (limit << 8 | in.byte()) % ((1u << 20) + 1);
  const std::size_t plan_payload = in.u32();
  const std::size_t plan_channel = in.byte() % 66;
  check_plan(plan_channel, plan_payload);

  cosmic::LcmReassembler reassembler(limit);
  while (!in.empty()) {
    std::size_t length = in.byte();
    length = length << 8 | in.byte();
    const std::uint64_t sender = in.byte();
    const auto view = in.bytes(length);
    // A buffer of exactly the datagram's size, so that reading past it is a finding for ASan.
    const std::vector<std::uint8_t> datagram(view.begin(), view.end());
    const auto parsed = cosmic::parse_lcm_datagram(datagram);
    if (!parsed) continue;
    check_datagram(*parsed, datagram);
    check_reassembly(reassembler, limit, sender, *parsed);
  }
  return 0;
}

#include "cosmic/lcm_reassembly.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace cosmic {

LcmReassembler::LcmReassembler(std::size_t max_message_size)
    : max_message_size_(max_message_size), budget_(std::max(kMinBudget, 2 * max_message_size)) {}

LcmReassembler::Partial* LcmReassembler::find_sender(std::uint64_t sender) {
  for (Partial& p : partials_)
    if (p.sender == sender) return &p;
  return nullptr;
}

// What a message's bookkeeping costs beyond its payload: a flag and a slice per fragment.
std::size_t LcmReassembler::bookkeeping_of(std::uint16_t fragment_count) {
  return std::size_t{fragment_count} * (1 + sizeof(std::pair<std::uint32_t, std::uint32_t>));
}

void LcmReassembler::drop(std::size_t index) {
  bytes_held_ -= partials_[index].data.size();
  bookkeeping_ -= bookkeeping_of(partials_[index].fragment_count);
  if (index + 1 != partials_.size()) partials_[index] = std::move(partials_.back());
  partials_.pop_back();
}

// Evicts the least recently touched messages until `bytes` more fit the budget and a slot is
// free; false when they cannot (bytes beyond the whole budget).
bool LcmReassembler::make_room(std::size_t bytes) {
  if (bytes > budget_) return false;
  while (!partials_.empty() && (bytes_held_ + bookkeeping_ + bytes > budget_ || partials_.size() >= kMaxSenders)) {
    const auto oldest = std::min_element(partials_.begin(), partials_.end(), [](const Partial& a, const Partial& b) {
      return a.last_touch < b.last_touch;
    });
    drop(static_cast<std::size_t>(oldest - partials_.begin()));
    ++abandoned_;
  }
  return true;
}

LcmReassembler::Partial* LcmReassembler::start(std::uint64_t sender, const LcmDatagram& fragment) {
  // Every fragment but the first carries at least one byte: more fragments than that is not a
  // sender's message but a way to make us keep bookkeeping.
  if (fragment.message_size > max_message_size_ || fragment.fragment_count > std::uint64_t{fragment.message_size} + 1 ||
      !make_room(fragment.message_size + bookkeeping_of(fragment.fragment_count)))
    return nullptr;
  Partial p;
  p.sender = sender;
  p.sequence = fragment.sequence;
  p.fragment_count = fragment.fragment_count;
  p.data.resize(fragment.message_size);
  p.received.assign(fragment.fragment_count, false);
  bytes_held_ += p.data.size();
  bookkeeping_ += bookkeeping_of(p.fragment_count);
  partials_.push_back(std::move(p));
  return &partials_.back();
}

void LcmReassembler::skip(std::uint64_t sender, std::uint32_t sequence) {
  if (Partial* p = find_sender(sender); p != nullptr && p->sequence == sequence)
    drop(static_cast<std::size_t>(p - partials_.data()));
  remember_finished(sender, sequence);
}

void LcmReassembler::remember_finished(std::uint64_t sender, std::uint32_t sequence) {
  finished_[next_finished_] = {sender, sequence};
  next_finished_ = (next_finished_ + 1) % finished_.size();
  finished_count_ = std::min(finished_count_ + 1, finished_.size());
}

LcmReassembler::Outcome LcmReassembler::add(std::uint64_t sender, const LcmDatagram& fragment) {
  if (!fragment.fragment || fragment.fragment_no >= fragment.fragment_count) return Outcome::refused;
  // A fragment of a message already delivered (a duplicate arriving late) starts nothing.
  const auto finished_end = finished_.begin() + static_cast<std::ptrdiff_t>(finished_count_);
  if (std::find(finished_.begin(), finished_end, std::pair{sender, fragment.sequence}) != finished_end)
    return Outcome::ignored;
  Partial* p = find_sender(sender);
  if (p != nullptr && p->sequence != fragment.sequence) {
    // The sender moved on: what it left unfinished is lost.
    drop(static_cast<std::size_t>(p - partials_.data()));
    ++abandoned_;
    p = nullptr;
  }
  if (p == nullptr) p = start(sender, fragment);
  if (p == nullptr) return Outcome::refused;
  if (fragment.message_size != p->data.size() || fragment.fragment_count != p->fragment_count ||
      p->received[fragment.fragment_no] ||
      std::uint64_t{fragment.fragment_offset} + fragment.data.size() > p->data.size()) {
    return Outcome::refused;
  }
  p->received[fragment.fragment_no] = true;
  ++p->fragments_received;
  p->slices.emplace_back(fragment.fragment_offset, static_cast<std::uint32_t>(fragment.data.size()));
  p->last_touch = ++clock_;
  if (fragment.fragment_no == 0) p->channel.assign(fragment.channel);
  if (!fragment.data.empty())
    std::memcpy(p->data.data() + fragment.fragment_offset, fragment.data.data(), fragment.data.size());
  if (p->fragments_received < p->fragment_count) return Outcome::pending;
  // Every fragment came once; the message is whole only when their slices tile it exactly
  // (slices that overlap leave a gap somewhere: the message is lost, not delivered with holes).
  std::sort(p->slices.begin(), p->slices.end());
  std::uint64_t covered = 0;
  for (const auto& [offset, length] : p->slices) {
    if (offset != covered) break;
    covered += length;
  }
  const bool whole = covered == p->data.size();
  completed_channel_ = std::move(p->channel);
  bytes_held_ -= p->data.size();
  completed_ = std::move(p->data);
  p->data.clear();  // moved from: drop() accounts nothing more for it
  remember_finished(sender, fragment.sequence);
  drop(static_cast<std::size_t>(p - partials_.data()));
  if (!whole) {
    ++abandoned_;
    return Outcome::refused;
  }
  return Outcome::complete;
}

}  // namespace cosmic

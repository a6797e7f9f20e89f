#include "famouso_afp.hpp"

#include <algorithm>
#include <cstring>

namespace cosmic::famouso {
namespace {

// Fragments whose header is 1 (2) bytes carry 7 (6) event bytes; FAMOUSO sizes an event's
// fragments from the last one backwards: 32 one-byte-header fragments, then up to 4064 more.
constexpr std::uint32_t kShortHeaderFragments = 32;

std::size_t payload_of(std::uint32_t remaining) { return kAfpMtu - afp_header_length(remaining); }

}  // namespace

std::size_t afp_header_length(std::uint32_t remaining) {
  std::size_t length = 1;
  while (length < 4 && remaining >= (1u << (7 * length - 2))) ++length;
  return length;
}

std::optional<AfpHeader> decode_afp_header(std::span<const std::uint8_t> fragment) {
  if (fragment.empty()) return std::nullopt;
  std::uint8_t h = fragment[0];
  std::size_t length = 1;
  while (h & 0x80) {
    ++length;
    h = static_cast<std::uint8_t>(h << 1);
  }
  // Extension headers (event sequence, FEC) are not used on CAN; a header longer than the frame
  // or than 3 bytes (19-bit sequence numbers) is not one FAMOUSO's CAN layer sends.
  if ((h & 0x40) || length > 3 || length >= fragment.size()) return std::nullopt;
  AfpHeader header;
  header.length = length;
  header.first = (h & 0x20) != 0;
  header.remaining = fragment[0] & (0x3Fu >> length);
  for (std::size_t i = 1; i < length; ++i) header.remaining = (header.remaining << 8) | fragment[i];
  return header;
}

std::size_t encode_afp_header(std::uint32_t remaining, bool first, std::span<std::uint8_t> out) {
  const std::size_t length = afp_header_length(remaining);
  for (std::size_t i = length; i > 0; --i) {
    out[i - 1] = static_cast<std::uint8_t>(remaining & 0xFF);
    remaining >>= 8;
  }
  // `length - 1` leading one bits, a zero, the extension flag (0), the first flag, then the
  // sequence number's high bits.
  const unsigned flags = 0xF8u | (first ? 1u : 0u);
  out[0] = static_cast<std::uint8_t>(out[0] | ((flags << (6 - length)) & 0xFF));
  return length;
}

std::uint32_t afp_fragment_count(std::size_t length) {
  const std::size_t short_capacity = kShortHeaderFragments * payload_of(0);
  if (length <= short_capacity) return static_cast<std::uint32_t>((length + payload_of(0) - 1) / payload_of(0));
  const std::size_t rest = length - short_capacity;
  const std::size_t per = payload_of(kShortHeaderFragments);
  return kShortHeaderFragments + static_cast<std::uint32_t>((rest + per - 1) / per);
}

AfpFragmenter::AfpFragmenter(std::span<const std::uint8_t> event)
    : rest_(event), remaining_(afp_fragment_count(event.size())) {}

std::size_t AfpFragmenter::next(std::span<std::uint8_t> out) {
  if (remaining_ == 0) return 0;
  --remaining_;
  std::fill(out.begin(), out.begin() + kAfpMtu, std::uint8_t{0});
  const std::size_t header = encode_afp_header(remaining_, first_, out);
  first_ = false;
  const std::size_t take = std::min(rest_.size(), kAfpMtu - header);
  std::copy_n(rest_.begin(), take, out.begin() + static_cast<std::ptrdiff_t>(header));
  rest_ = rest_.subspan(take);
  return header + take;
}

AfpReassembler::AfpReassembler(AfpLimits limits)
    : limits_(limits), slots_(std::max<std::size_t>(1, limits.max_partial_events)) {}

AfpReassembler::Slot* AfpReassembler::find(std::uint32_t source) {
  for (Slot& s : slots_) {
    if (s.used && s.source == source) return &s;
  }
  return nullptr;
}

AfpReassembler::Slot& AfpReassembler::claim(std::uint32_t source, AfpResult& result) {
  Slot* chosen = nullptr;
  for (Slot& s : slots_) {
    if (!s.used) {
      chosen = &s;
      break;
    }
    if (!chosen || s.last < chosen->last) chosen = &s;  // the one idle longest
  }
  if (chosen->used) result.displaced = chosen->source;
  chosen->used = true;
  chosen->source = source;
  chosen->data.clear();
  return *chosen;
}

AfpResult AfpReassembler::accept(std::uint32_t source, std::span<const std::uint8_t> fragment, std::size_t max_event,
                                 Nanos now) {
  AfpResult result;
  Slot* slot = find(source);
  const auto header = decode_afp_header(fragment);
  if (!header) {
    result.outcome = AfpOutcome::rejected;
    return result;
  }
  if (header->first) {
    if (slot) {  // a new event before the last fragment of the current one: that one is lost
      result.dropped_event = true;
      slot->used = false;
    }
    slot = &claim(source, result);
  } else if (!slot || header->remaining != slot->expected) {
    // CAN keeps the order of one identifier: a gap or a fragment of no known event is a loss.
    if (slot) {
      slot->used = false;
      result.dropped_event = true;
    }
    result.outcome = AfpOutcome::rejected;
    return result;
  }
  const auto bytes = fragment.subspan(header->length);
  if (slot->data.size() + bytes.size() > max_event) {
    slot->used = false;
    result.outcome = AfpOutcome::rejected;
    return result;
  }
  slot->data.insert(slot->data.end(), bytes.begin(), bytes.end());
  slot->last = now;
  if (header->remaining == 0) {
    slot->used = false;  // the data stays valid until this slot is claimed again
    result.outcome = AfpOutcome::complete;
    result.event = slot->data;
    return result;
  }
  slot->expected = header->remaining - 1;
  return result;
}

std::optional<Nanos> AfpReassembler::next_deadline() const {
  std::optional<Nanos> earliest;
  for (const Slot& s : slots_) {
    if (s.used && (!earliest || s.last + limits_.idle_timeout < *earliest)) earliest = s.last + limits_.idle_timeout;
  }
  return earliest;
}

void AfpReassembler::clear() {
  for (Slot& s : slots_) s.used = false;
}

}  // namespace cosmic::famouso

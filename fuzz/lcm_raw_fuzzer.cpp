// One LCM message on a raw channel (a native binding or `encoding: raw`), as the LCM adapter's raw
// format unit reads it (lib/adapters/lcm/src/lcm_message_format.cpp). The first input byte picks
// max_message_size (0-255, or no limit); the rest is the message. Checked beyond "no crash": a
// message is accepted exactly when it fits the limit, the event is the message itself (a view, the
// channel's subject, the arrival as creation time, no origin), and writing the event gives the
// message back.
#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_input.hpp"
#include "lcm_message_format.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint64_t limit = data[0] == 0xFF ? UINT64_MAX : data[0];
  const std::span<const std::uint8_t> message(data + 1, size - 1);
  const auto format = cosmic::lcm_detail::make_lcm_message_format(cosmic::LcmEncoding::raw);
  const cosmic::lcm_detail::LcmArrival arrival{0x5eed, 1'700'000'000'000'000'000};
  cosmic::InboundEvent event;
  const bool accepted = format->decode(message, arrival, limit, event);
  require(accepted == (message.size() <= limit));
  if (!accepted) return 0;
  require(event.payload.data() == message.data() && event.payload.size() == message.size());
  require(event.header.subject == arrival.subject && event.header.created_ns == arrival.realtime_ns);
  require(event.header.origin == 0 && event.header.sequence == 0 && event.header.hop_count == 0);
  require(event.identity.needs_fingerprint_loop_guard());

  cosmic::lcm_detail::LcmHeaderBuffer header{};
  cosmic::lcm_detail::LcmMessageParts parts{};
  const std::size_t count = format->encode(cosmic::OutboundEvent{1, event.header, event.payload}, header, parts);
  std::vector<std::uint8_t> written;
  for (std::size_t i = 0; i < count; ++i) written.insert(written.end(), parts[i].begin(), parts[i].end());
  require(written.size() == message.size());
  require(message.empty() || std::memcmp(written.data(), message.data(), message.size()) == 0);
  return 0;
}

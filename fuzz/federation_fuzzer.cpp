// A federation announcement as it arrives from another gateway (cosmic::decode_announcement,
// lib/federation/include/cosmic/federation.hpp), then applied to a view of the peers and turned
// into admission's reservations by network.
#include <cmath>
#include <cstdint>
#include <string>

#include "cosmic/federation.hpp"
#include "cosmic/federation_view.hpp"
#include "cosmic/knowledge_base.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const cosmic::DecodedAnnouncement decoded = cosmic::decode_announcement(text);
  require(decoded.announcement.has_value() !=
          !decoded.error.empty());  // an announcement or a reason, never both or neither
  if (!decoded.announcement) return 0;
  const cosmic::Announcement& a = *decoded.announcement;
  // What decodes encodes to a text that decodes to the same announcement.
  const cosmic::DecodedAnnouncement again = cosmic::decode_announcement(cosmic::encode(a));
  require(again.announcement && *again.announcement == a);  // encode(decode(x)) decodes to the same announcement
  require(a.gateway != 0 && a.segments.size() <= cosmic::kMaxAnnouncedSegments &&
          a.channels.size() <= cosmic::kMaxAnnouncedChannels);
  cosmic::FederationView view(0x1);
  view.apply(cosmic::FederationMessage{cosmic::FederationMessage::Kind::announcement, "writer", a.gateway, text},
             cosmic::Nanos(1));
  for (const auto& [network, reservations] : view.reservations()) {
    require(std::isfinite(reservations.bits_per_second) && reservations.bits_per_second >= 0);
    for (const auto& frame : reservations.frames) require(frame.period.count() > 0);
  }
  // And what admission makes of it: a segment of this gateway on each of the first networks.
  std::vector<cosmic::SegmentSpec> segments;
  for (const auto& announced : a.segments) {
    const std::string prefix = std::string(cosmic::to_string(announced.type)) + ":";
    if (segments.size() == 4 || announced.network.rfind(prefix, 0) != 0 || announced.network.size() == prefix.size())
      continue;
    cosmic::SegmentSpec s;
    s.name = "s" + std::to_string(segments.size());
    s.type = announced.type;
    s.network = announced.network.substr(prefix.size());
    segments.push_back(s);
  }
  cosmic::KnowledgeBase kb(cosmic::GatewaySpec{}, segments);
  kb.set_peer_reservations(view.reservations());
  for (const auto& load : kb.loads()) require(load.peers >= 0 && !std::isnan(load.utilization));
  return 0;
}

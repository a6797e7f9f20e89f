// A federation announcement as it arrives from another gateway (cosmic::decode_announcement,
// lib/federation/include/cosmic/federation.hpp), then applied to a view of the peers and turned
// into admission's reservations for a shared DDS network and a shared CAN bus.
#include <cmath>
#include <cstdint>
#include <string>

#include "cosmic/federation.hpp"
#include "cosmic/federation_view.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const cosmic::DecodedAnnouncement decoded = cosmic::decode_announcement(text);
  require(decoded.announcement.has_value() != !decoded.error.empty());  // an announcement or a reason, never both or neither
  if (!decoded.announcement) return 0;
  const cosmic::Announcement& a = *decoded.announcement;
  // What decodes encodes to a text that decodes to the same announcement.
  const cosmic::DecodedAnnouncement again = cosmic::decode_announcement(cosmic::encode(a));
  require(again.announcement && *again.announcement == a);  // encode(decode(x)) decodes to the same announcement
  require(a.gateway != 0 && a.segments.size() <= cosmic::kMaxAnnouncedSegments && a.channels.size() <= cosmic::kMaxAnnouncedChannels);
  cosmic::FederationView view(0x1);
  view.apply(cosmic::FederationMessage{cosmic::FederationMessage::Kind::announcement, "writer", a.gateway, text}, cosmic::Nanos(1));
  cosmic::SegmentSpec lan;
  lan.name = "lan";
  lan.type = cosmic::SegmentType::dds;
  cosmic::SegmentSpec bus;
  bus.name = "bus";
  bus.type = cosmic::SegmentType::can;
  bus.network = "body";
  for (const auto& [segment, reservations] : view.reservations_for({lan, bus})) {
    require(std::isfinite(reservations.load) && reservations.load >= 0);
    for (const auto& frame : reservations.frames) require(frame.period.count() > 0);
  }
  return 0;
}

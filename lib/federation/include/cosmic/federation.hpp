// Federation of several gateways (docs/federation.md): what one gateway announces about itself to
// the others, and the codec of that announcement. Pure values and functions, no I/O: the transport
// (a DDS topic, see federation_link.hpp) moves the encoded text, FederationView keeps what was heard.
//
// An announcement says who the gateway is, which networks its segments attach (a network identity
// that is the same on every gateway attached to it), what its own channels reserve there (IP: the
// share of the bandwidth; CAN: the frames with their identifiers, lengths and periods, which the
// others' response-time analysis counts like background frames) and each channel's hops with their
// bounds. A gateway describes only itself: decode() refuses what is malformed or out of range, and
// FederationView refuses what claims another gateway's identity.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/network_identity.hpp"

namespace cosmic {

class KnowledgeBase;

// Bounds of an announcement the codec accepts (each refusal names the one exceeded).
inline constexpr double kMaxAnnouncedBitsPerSecond = 1e12;
inline constexpr Nanos kMaxAnnouncedDuration{86'400'000'000'000};  // a day
inline constexpr std::size_t kMaxAnnouncementBytes = 1u << 20;
inline constexpr std::size_t kMaxAnnouncedSegments = 64;
inline constexpr std::size_t kMaxAnnouncedChannels = 4096;
inline constexpr std::size_t kMaxAnnouncedFrames = 4096;  // per segment
inline constexpr std::size_t kMaxAnnouncedHops = 64;      // per channel
inline constexpr std::size_t kMaxAnnouncedName = 128;     // characters of a name or network identity
inline constexpr std::string_view kFederationFormat = "cosmic-federation/1";

// One frame a gateway's channel puts on a shared CAN bus.
struct AnnouncedFrame {
  std::string channel;
  std::uint32_t can_id = 0;  // 11 or 29 bits
  bool extended = true;
  std::uint32_t length = 8;  // data bytes of one frame
  Nanos period{0};           // minimum inter-arrival time of the frame (> 0)
  Nanos jitter{0};
  // HRT channels: the longest response time the frame may have with its channel still admitted
  // (its response time plus the channel's slack); other gateways' binds must keep it within.
  std::optional<Nanos> deadline;
  friend bool operator==(const AnnouncedFrame&, const AnnouncedFrame&) = default;
};

struct AnnouncedSegment {
  std::string name;  // the gateway's own name for it
  SegmentType type = SegmentType::dds;
  std::string network;  // network_identity(); empty: not shared with other gateways
  double max_utilization = 0.7;
  double load = 0;  // share of the network the gateway's channels reserve (background excluded)
  // DDS and LCM: the bandwidth behind `load`, which other gateways relate to their own `bandwidth`
  // of the network (their shares would differ where the gateways declare different bandwidths).
  double reserved_bps = 0;
  std::vector<AnnouncedFrame> frames;  // CAN: the frames behind `load`
  friend bool operator==(const AnnouncedSegment&, const AnnouncedSegment&) = default;
};

struct AnnouncedHop {
  std::string segment;
  HopRole role = HopRole::publisher;
  std::optional<Nanos> latency;  // nullopt: unbounded
  friend bool operator==(const AnnouncedHop&, const AnnouncedHop&) = default;
};

struct AnnouncedChannel {
  std::string name;
  std::uint64_t subject = 0;
  ChannelClass cls = ChannelClass::nrt;
  Verdict verdict = Verdict::bound;
  std::vector<AnnouncedHop> hops;
  std::optional<Nanos> end_to_end;  // the whole path, upstream included; nullopt: unbounded
  // The definition, for gateways downstream to compare with theirs.
  std::optional<Nanos> period;
  std::optional<Nanos> reaction_time;
  std::optional<Nanos> temp_validity;
  std::uint64_t payload = 0;
  // Where its events come from before this gateway: the hops on gateways upstream, and the age the
  // events arrive with (0: they start here; nullopt: unbounded).
  std::vector<PathHop> upstream;
  std::optional<Nanos> upstream_age{Nanos(0)};
  // Its bounds do not hold at run time now (the gateway's runtime state `violated`).
  bool violated = false;
  friend bool operator==(const AnnouncedChannel&, const AnnouncedChannel&) = default;
};

struct Announcement {
  std::uint64_t gateway = 0;  // GatewayIdentity::id, never 0
  std::string name;
  std::uint64_t revision = 0;  // grows with every change the gateway announces
  Nanos residence{0};          // its gateway.residence_bound
  std::vector<AnnouncedSegment> segments;
  std::vector<AnnouncedChannel> channels;
  // A bind in its claim window: the segments as they will be once it is committed (a superset of
  // `segments`' reservations). Gateways with a higher id count it at once, so of two binds racing
  // for one network the lower id goes first (docs/federation.md, "Concurrent binds").
  std::optional<std::vector<AnnouncedSegment>> claim;
  friend bool operator==(const Announcement&, const Announcement&) = default;
};

// What this gateway announces: its segments' networks and reservations and its bound channels'
// hops, from the knowledge base; `violated` names the channels whose bounds do not hold at run
// time now. `revision` is the caller's counter.
Announcement announcement_of(const GatewayIdentity& self, const KnowledgeBase& kb, std::uint64_t revision,
                             const std::set<std::string>& violated = {});

std::string encode(const Announcement& announcement);

struct DecodedAnnouncement {
  std::optional<Announcement> announcement;
  std::string error;  // why not, when announcement is empty
};
// Never throws; refuses malformed JSON, unknown formats, missing or mistyped fields, negative or
// non-finite numbers, loads outside 0..1, identifiers outside 29 bits, periods under 1 us, a
// frame's jitter above 1 s and anything over the kMaxAnnounced* bounds.
DecodedAnnouncement decode_announcement(std::string_view text);

// "00000000deadbeef": how ids are written in announcements, logs and `cosmicctl peers`.
std::string gateway_id_text(std::uint64_t id);

}  // namespace cosmic

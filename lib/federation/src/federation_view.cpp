#include "cosmic/federation_view.hpp"

#include <algorithm>
#include <optional>
#include <set>

namespace cosmic {
namespace {

// A writer's name as a log line may quote it (it comes from the network).
std::string quoted_source(const std::string& source) {
  std::string out;
  for (const char c : source.substr(0, 64)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out;
}

// Two announcements of one CAN identifier: the heavier of each property, so neither hides load.
void merge_heaviest(CanBackgroundFrame& kept, const CanBackgroundFrame& other) {
  kept.period = std::min(kept.period, other.period);
  kept.length = std::max(kept.length, other.length);
  kept.jitter = std::max(kept.jitter, other.jitter);
  if (other.deadline && (!kept.deadline || *other.deadline < *kept.deadline)) kept.deadline = other.deadline;
}

// The path `channel` gives its events before the networks it sends them onto: its upstream, its
// own publisher hops, and the age its events leave it with.
UpstreamPath path_before(const Announcement& peer, const AnnouncedChannel& channel) {
  UpstreamPath path{peer.name,        channel.name,          channel.subject,       channel.cls,
                    channel.period,   channel.reaction_time, channel.temp_validity, channel.payload,
                    channel.upstream, channel.upstream_age,  channel.violated};
  Nanos slowest{0};
  for (const AnnouncedHop& hop : channel.hops) {
    if (hop.role != HopRole::publisher) continue;
    path.hops.push_back(PathHop{peer.name, hop.segment, hop.role, hop.latency, peer.gateway});
    if (!hop.latency) path.age.reset();
    if (hop.latency) slowest = std::max(slowest, *hop.latency);
  }
  if (path.age) path.age = *path.age + slowest + peer.residence;
  return path;
}

// A path that passes `self` (the channel goes round a ring of gateways back to this one) or any
// gateway twice is no upstream: following it would grow the path with every announcement.
bool loops(const UpstreamPath& path, std::uint64_t self) {
  std::set<std::uint64_t> seen;
  std::optional<std::uint64_t> current;  // a gateway's hops come together
  for (const PathHop& hop : path.hops) {
    if (hop.gateway_id == self) return true;
    if (hop.gateway_id == current) continue;
    if (!seen.insert(hop.gateway_id).second) return true;
    current = hop.gateway_id;
  }
  return false;
}

// Of two gateways sending one subject onto one network, the slower path counts.
bool slower(const UpstreamPath& a, const UpstreamPath& b) { return !a.age || (b.age && *a.age > *b.age); }

const std::string* network_of(const Announcement& peer, const std::string& segment) {
  for (const AnnouncedSegment& s : peer.segments) {
    if (s.name == segment) return s.network.empty() ? nullptr : &s.network;
  }
  return nullptr;
}

}  // namespace

const char* to_string(PeerState value) {
  switch (value) {
    case PeerState::alive:
      return "alive";
    case PeerState::lost:
      return "lost";
    case PeerState::left:
      return "left";
  }
  return "?";
}

FederationView::FederationView(std::uint64_t self, std::size_t max_peers) : self_(self), max_peers_(max_peers) {}

bool FederationView::refuse(const FederationMessage& message, const std::string& why, std::string* refusal) {
  ++counters_.refused;
  counters_.last_refusal = why + " (from writer " + quoted_source(message.source) + ")";
  if (refusal) *refusal = counters_.last_refusal;
  return false;
}

PeerRecord* FederationView::by_source(const std::string& source) {
  for (auto& [id, peer] : peers_) {
    if (peer.source == source) return &peer;
  }
  return nullptr;
}

std::string FederationView::cheap_refusal(const FederationMessage& message) {
  if (message.key == self_) return "announcement claims this gateway's own id " + gateway_id_text(self_);
  if (const PeerRecord* own = by_source(message.source); own && own->announcement.gateway != message.key) {
    return "writer announces gateway " + gateway_id_text(own->announcement.gateway) + " (" + own->announcement.name +
           ") and now also " + gateway_id_text(message.key) + ": one gateway per writer";
  }
  const auto it = peers_.find(message.key);
  if (it != peers_.end() && it->second.source != message.source && it->second.state == PeerState::alive) {
    // Kept to take over once that writer is gone: one per writer, and never in place of another
    // writer's (a spoofer cannot displace a rejoined gateway's waiting announcement).
    std::erase_if(pending_, [&](const auto& p) { return p.second.source == message.source && p.first != message.key; });
    const auto waiting = pending_.find(message.key);
    if (waiting == pending_.end() || waiting->second.source == message.source) pending_[message.key] = message;
    return "gateway " + gateway_id_text(message.key) + " (" + it->second.announcement.name +
           ") is announced by another writer";
  }
  if (it == peers_.end() && peers_.size() >= max_peers_)
    return "more than " + std::to_string(max_peers_) + " gateways in the federation";
  return {};
}

bool FederationView::take_announcement(const FederationMessage& message, Nanos now, std::string* refusal) {
  if (!message.refusal.empty()) return refuse(message, message.refusal, refusal);
  if (std::string why = cheap_refusal(message); !why.empty()) return refuse(message, why, refusal);
  DecodedAnnouncement decoded = decode_announcement(message.body);
  if (!decoded.announcement) return refuse(message, decoded.error, refusal);
  Announcement& a = *decoded.announcement;
  if (a.gateway != message.key) {
    return refuse(
        message,
        "announcement of gateway " + gateway_id_text(a.gateway) + " filed under " + gateway_id_text(message.key),
        refusal);
  }
  auto it = peers_.find(a.gateway);
  if (it == peers_.end()) {
    it = peers_.emplace(a.gateway, PeerRecord{}).first;
    it->second.first_heard = now;
  } else if (it->second.source == message.source && a.revision <= it->second.announcement.revision &&
             it->second.state == PeerState::alive) {
    ++counters_.stale;
    it->second.last_heard = now;
    return false;
  }
  PeerRecord& peer = it->second;
  if (peer.state != PeerState::alive || peer.announcements == 0) peer.state_since = now;
  peer.announcement = std::move(a);
  peer.source = message.source;
  peer.subject = message.subject;
  peer.last_heard = now;
  peer.state = PeerState::alive;
  ++peer.announcements;
  ++counters_.applied;
  pending_.erase(peer.announcement.gateway);
  return true;
}

bool FederationView::apply(const FederationMessage& message, Nanos now, std::string* refusal) {
  ++counters_.received;
  if (refusal) refusal->clear();
  if (message.kind == FederationMessage::Kind::announcement) return take_announcement(message, now, refusal);
  PeerRecord* peer = by_source(message.source);
  if (!peer) {
    // A writer that was refused: what it left waiting for a takeover goes with it.
    if (message.kind != FederationMessage::Kind::alive) {
      std::erase_if(pending_, [&](const auto& p) { return p.second.source == message.source; });
    }
    return false;
  }
  const PeerState next = message.kind == FederationMessage::Kind::alive  ? PeerState::alive
                         : message.kind == FederationMessage::Kind::lost ? PeerState::lost
                                                                         : PeerState::left;
  peer->last_heard = now;
  if (peer->state == next || peer->state == PeerState::left) return false;  // left is final until it announces again
  peer->state = next;
  peer->state_since = now;
  // A newer writer of the same gateway waited for this one to go.
  if (next != PeerState::alive) {
    if (const auto pending = pending_.find(peer->announcement.gateway); pending != pending_.end()) {
      const FederationMessage takeover = std::move(pending->second);
      pending_.erase(pending);
      take_announcement(takeover, now, refusal);
    }
  }
  return true;
}

std::size_t FederationView::alive_peers() const {
  return static_cast<std::size_t>(
      std::count_if(peers_.begin(), peers_.end(), [](const auto& p) { return p.second.state == PeerState::alive; }));
}

void FederationView::forget_before(Nanos when) {
  std::erase_if(peers_,
                [&](const auto& p) { return p.second.state != PeerState::alive && p.second.state_since < when; });
  std::erase_if(pending_, [&](const auto& p) { return !peers_.count(p.first); });
}

bool FederationView::shared(const std::string& network) const {
  if (network.empty()) return false;
  for (const auto& [id, peer] : peers_) {
    if (peer.state != PeerState::alive) continue;
    for (const AnnouncedSegment& s : peer.announcement.segments) {
      if (s.network == network) return true;
    }
  }
  return false;
}

PeerNetworks FederationView::reservations() const {
  PeerNetworks out;
  std::map<std::string, std::map<std::pair<std::uint32_t, bool>, CanBackgroundFrame>>
      frames;                                                            // by network, by identifier
  std::map<std::string, std::map<std::uint64_t, UpstreamPath>> senders;  // by network, by subject
  for (const auto& [id, peer] : peers_) {
    if (peer.state != PeerState::alive) continue;
    for (const AnnouncedChannel& channel : peer.announcement.channels) {
      std::optional<UpstreamPath> path;  // built once per channel, when it sends onto a shared network
      for (const AnnouncedHop& hop : channel.hops) {
        const std::string* network =
            hop.role == HopRole::subscriber ? network_of(peer.announcement, hop.segment) : nullptr;
        if (!network) continue;
        if (!path) path = path_before(peer.announcement, channel);
        if (loops(*path, self_)) break;
        auto [kept, fresh] = senders[*network].emplace(channel.subject, *path);
        if (!fresh && slower(*path, kept->second)) kept->second = *path;
      }
    }
    // A bind in its claim window on a gateway with a lower id goes first: count it already.
    const bool claim_first = peer.announcement.claim && id < self_;
    for (const AnnouncedSegment& theirs : claim_first ? *peer.announcement.claim : peer.announcement.segments) {
      if (theirs.network.empty()) continue;
      PeerReservations& r = out[theirs.network];
      r.bits_per_second += theirs.reserved_bps;
      for (const AnnouncedFrame& f : theirs.frames) {
        CanBackgroundFrame frame{peer.announcement.name + ":" + f.channel,
                                 f.can_id,
                                 f.extended,
                                 f.length,
                                 f.period,
                                 f.jitter,
                                 "gateway " + peer.announcement.name + " (" + gateway_id_text(id) + ")",
                                 f.deadline};
        const auto [kept, fresh] = frames[theirs.network].emplace(std::make_pair(f.can_id, f.extended), frame);
        if (!fresh) merge_heaviest(kept->second, frame);
      }
    }
  }
  for (auto& [network, by_subject] : senders) {
    for (auto& [subject, path] : by_subject) out[network].senders.push_back(std::move(path));
  }
  counters_.frames_over_cap = 0;
  for (auto& [network, by_id] : frames) {
    std::vector<CanBackgroundFrame>& list = out[network].frames;
    for (auto& [key, frame] : by_id) {
      if (list.size() >= kMaxPeerFramesPerNetwork) {
        ++counters_.frames_over_cap;
        continue;
      }
      list.push_back(std::move(frame));
    }
  }
  return out;
}

}  // namespace cosmic

#include "cosmic/federation_view.hpp"

#include <algorithm>
#include <set>

#include "cosmic/can_background.hpp"

namespace cosmic {
namespace {

// A writer's name as a log line may quote it (it comes from the network).
std::string quoted_source(const std::string& source) {
  std::string out;
  for (const char c : source.substr(0, 64)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out;
}

}  // namespace

const char* to_string(PeerState value) {
  switch (value) {
    case PeerState::alive: return "alive";
    case PeerState::lost: return "lost";
    case PeerState::left: return "left";
  }
  return "?";
}

FederationView::FederationView(std::uint64_t self, std::size_t max_peers) : self_(self), max_peers_(max_peers) {}

bool FederationView::refuse(const FederationMessage& message, std::string why, std::string* refusal) {
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

bool FederationView::take_announcement(const FederationMessage& message, Nanos now, std::string* refusal) {
  DecodedAnnouncement decoded = decode_announcement(message.body);
  if (!decoded.announcement) return refuse(message, decoded.error, refusal);
  Announcement& a = *decoded.announcement;
  if (a.gateway != message.key) {
    return refuse(message, "announcement of gateway " + gateway_id_text(a.gateway) + " filed under " + gateway_id_text(message.key), refusal);
  }
  if (a.gateway == self_) return refuse(message, "announcement claims this gateway's own id " + gateway_id_text(self_), refusal);
  auto it = peers_.find(a.gateway);
  if (it != peers_.end() && it->second.source != message.source && it->second.state == PeerState::alive) {
    return refuse(message, "gateway " + gateway_id_text(a.gateway) + " (" + it->second.announcement.name +
                               ") is announced by another writer", refusal);
  }
  if (it == peers_.end()) {
    if (peers_.size() >= max_peers_) {
      return refuse(message, "more than " + std::to_string(max_peers_) + " gateways in the federation", refusal);
    }
    it = peers_.emplace(a.gateway, PeerRecord{}).first;
    it->second.first_heard = now;
  } else if (it->second.source == message.source && a.revision <= it->second.announcement.revision && it->second.state == PeerState::alive) {
    ++counters_.stale;
    it->second.last_heard = now;
    return false;
  }
  PeerRecord& peer = it->second;
  const bool was_alive = peer.state == PeerState::alive;
  peer.announcement = std::move(a);
  peer.source = message.source;
  peer.last_heard = now;
  if (!was_alive || peer.announcements == 0) peer.state_since = now;
  peer.state = PeerState::alive;
  ++peer.announcements;
  ++counters_.applied;
  return true;
}

bool FederationView::apply(const FederationMessage& message, Nanos now, std::string* refusal) {
  ++counters_.received;
  if (refusal) refusal->clear();
  if (message.kind == FederationMessage::Kind::announcement) return take_announcement(message, now, refusal);
  PeerRecord* peer = by_source(message.source);
  if (!peer) return false;  // a writer never heard from (or a foreign topic's writer): nothing to change
  const PeerState next = message.kind == FederationMessage::Kind::alive ? PeerState::alive
                         : message.kind == FederationMessage::Kind::lost ? PeerState::lost
                                                                          : PeerState::left;
  peer->last_heard = now;
  if (peer->state == next) return false;
  if (peer->state == PeerState::left) return false;  // left is final until it announces again
  peer->state = next;
  peer->state_since = now;
  return true;
}

std::size_t FederationView::alive_peers() const {
  return static_cast<std::size_t>(std::count_if(peers_.begin(), peers_.end(), [](const auto& p) { return p.second.state == PeerState::alive; }));
}

void FederationView::forget_before(Nanos when) {
  std::erase_if(peers_, [&](const auto& p) { return p.second.state != PeerState::alive && p.second.state_since < when; });
}

std::map<std::string, PeerReservations> FederationView::reservations_for(const std::vector<SegmentSpec>& segments) const {
  std::map<std::string, PeerReservations> out;
  for (const SegmentSpec& segment : segments) {
    const std::string network = network_identity(segment);
    if (network.empty()) continue;
    PeerReservations r;
    std::set<std::pair<std::uint32_t, bool>> seen;
    bool any = false;
    for (const auto& [id, peer] : peers_) {
      if (peer.state != PeerState::alive) continue;
      for (const AnnouncedSegment& theirs : peer.announcement.segments) {
        if (theirs.network != network || theirs.type != segment.type) continue;
        any = true;
        if (segment.type != SegmentType::can) {
          r.load += theirs.load;
          continue;
        }
        for (const AnnouncedFrame& f : theirs.frames) {
          if (!seen.emplace(f.can_id, f.extended).second) continue;
          r.frames.push_back(CanBackgroundFrame{peer.announcement.name + ":" + f.channel, f.can_id, f.extended, f.length, f.period,
                                                f.jitter, "gateway " + peer.announcement.name + " (" + gateway_id_text(id) + ")"});
        }
      }
    }
    if (!any) continue;
    if (segment.type == SegmentType::can) {
      CanSegmentProperties bus = segment.can;
      bus.background = r.frames;
      r.load = background_utilization(bus);
    }
    out.emplace(segment.name, std::move(r));
  }
  return out;
}

}  // namespace cosmic

// What this gateway knows of the other gateways of its federation: their last announcements and
// whether they are alive, and from that what they reserve on the networks this gateway's segments
// attach. Fed by a FederationLink's messages; no I/O. One owner (the daemon's control thread).
//
// A peer is trusted to describe itself only. Refused and counted (never applied): an announcement
// that does not decode, one filed under another gateway's id than it names, one naming this
// gateway's id, one naming a gateway another writer announces while that writer is alive, and a
// new gateway beyond max_peers. An older or repeated revision is ignored (counted as stale).
// A gateway that left (withdrew) stays `left` until it announces again; lost comes back on liveliness.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "cosmic/federation.hpp"
#include "cosmic/knowledge_base.hpp"

namespace cosmic {

struct FederationMessage {
  enum class Kind {
    announcement,  // `body` is an encoded Announcement filed under `key`
    withdrawn,     // the writer disposed its announcement: the gateway left
    lost,          // the writer's liveliness lapsed (lease): stopped, killed or cut off
    alive,         // the writer's liveliness is back
  };
  Kind kind = Kind::announcement;
  std::string source;     // the writer (DDS: its GUID), as the transport identifies it
  std::uint64_t key = 0;  // the gateway id the transport filed it under; 0 when it cannot tell
  std::string body;
};

enum class PeerState { alive, lost, left };
const char* to_string(PeerState value);

struct PeerRecord {
  Announcement announcement;
  std::string source;
  PeerState state = PeerState::alive;
  Nanos first_heard{0};
  Nanos last_heard{0};   // last announcement or liveliness change
  Nanos state_since{0};
  std::uint64_t announcements = 0;  // applied
};

struct FederationCounters {
  std::uint64_t received = 0;  // messages of every kind
  std::uint64_t applied = 0;   // announcements taken
  std::uint64_t stale = 0;     // older or repeated revisions
  std::uint64_t refused = 0;
  std::string last_refusal;    // why, with the source
};

class FederationView {
 public:
  static constexpr std::size_t kDefaultMaxPeers = 256;
  explicit FederationView(std::uint64_t self, std::size_t max_peers = kDefaultMaxPeers);

  // True when what admission sees (reservations_for) may have changed. `refusal`, when given,
  // receives the reason of a refused message (empty otherwise).
  bool apply(const FederationMessage& message, Nanos now, std::string* refusal = nullptr);

  // Peers by gateway id (lost and left ones included, until forget_before()).
  const std::map<std::uint64_t, PeerRecord>& peers() const { return peers_; }
  std::size_t alive_peers() const;
  // Drops peers lost or left before `when` from peers().
  void forget_before(Nanos when);
  const FederationCounters& counters() const { return counters_; }

  // What the alive peers reserve on the networks of `segments` (by segment name; segments with no
  // network identity or no peer on it are absent). Frames announced by two peers count once.
  std::map<std::string, PeerReservations> reservations_for(const std::vector<SegmentSpec>& segments) const;

 private:
  bool refuse(const FederationMessage& message, std::string why, std::string* refusal);
  bool take_announcement(const FederationMessage& message, Nanos now, std::string* refusal);
  PeerRecord* by_source(const std::string& source);

  std::uint64_t self_;
  std::size_t max_peers_;
  std::map<std::uint64_t, PeerRecord> peers_;
  FederationCounters counters_;
};

}  // namespace cosmic

// What this gateway knows of the other gateways of its federation: their last announcements and
// whether they are alive, and from that what they reserve on the networks this gateway's segments
// attach. Fed by a FederationLink's messages; no I/O. One owner (the daemon's control thread).
//
// A peer is trusted to describe itself only. Refused and counted (never applied): an announcement
// the transport refuses (FederationMessage::refusal), one that does not decode, one filed under another gateway's id
// than it names, one naming this gateway's id, one from a writer that already announces another gateway (one gateway
// per writer), one naming a gateway another writer announces while that writer is alive, and a new gateway beyond
// max_peers. The cheap checks (ids, writer) run before the body is decoded. The latest announcement refused only
// because its gateway's writer is alive is kept (one per gateway) and applied once that writer is lost or left: a
// gateway that rejoined with a new writer before its old one was gone is taken over then. An older or repeated revision
// is ignored (counted as stale). A gateway that left (withdrew) stays `left` until it announces again; a lost one comes
// back when its writer is matched again.
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
    lost,          // the writer is gone without withdrawing (its lease expired): killed or cut off
    alive,         // the writer is back (matched again)
  };
  Kind kind = Kind::announcement;
  std::string source;     // the writer (DDS: its GUID), as the transport identifies it
  std::uint64_t key = 0;  // the gateway id the transport filed it under; 0 when it cannot tell
  std::string body;
  // On a secure federation segment (docs/federation.md): the certificate subject the sender
  // authenticated with, as the transport proved it (empty: not secure, or nothing proves one), and
  // why the transport refuses the sender (an authenticated gateway gateway.federation.peers does not
  // list, a participant that did not authenticate): such an announcement is counted as refused and
  // never applied. `awaiting_authentication`: the refusal only reports that the sender's handshake
  // has not ended yet; the transport still holds the announcement and delivers it again once it does.
  std::string subject{};
  std::string refusal{};
  bool awaiting_authentication = false;
};

enum class PeerState { alive, lost, left };
const char* to_string(PeerState value);

struct PeerRecord {
  Announcement announcement;
  std::string source;
  std::string subject;  // its authenticated subject (FederationMessage::subject), empty when none
  PeerState state = PeerState::alive;
  Nanos first_heard{0};
  Nanos last_heard{0};  // last announcement or change of state
  Nanos state_since{0};
  std::uint64_t announcements = 0;  // applied
};

struct FederationCounters {
  std::uint64_t received = 0;  // messages of every kind
  std::uint64_t applied = 0;   // announcements taken
  std::uint64_t stale = 0;     // older or repeated revisions
  std::uint64_t refused = 0;
  std::string last_refusal;                   // why, with the source
  mutable std::uint64_t frames_over_cap = 0;  // at the last reservations()
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
  // Announcements waiting for their gateway's current writer to go (a rejoin, or a spoof whose
  // writer is still there).
  std::size_t pending_takeovers() const { return pending_.size(); }

  // What the alive peers reserve, by network identity (for KnowledgeBase::set_peer_reservations).
  // A CAN identifier announced by several peers counts once, as the heaviest of them (shortest
  // period, longest frame, largest jitter), so no peer can hide another's frame; at most
  // kMaxPeerFramesPerNetwork identifiers per network (the lowest, which delay the most), the rest
  // counted in counters().frames_over_cap. `senders`: the channels peers send onto the network,
  // with the path before it, one per subject (the slowest path when several peers send it); a path
  // through this gateway or through any gateway twice (a ring) is left out. A peer with a lower gateway id than this
  // one's that is claiming (a bind in its claim window) counts with what it claims.
  static constexpr std::size_t kMaxPeerFramesPerNetwork = 4096;
  PeerNetworks reservations() const;
  // Whether an alive peer attaches `network` (a bind adding load there must claim it first).
  bool shared(const std::string& network) const;

 private:
  bool refuse(const FederationMessage& message, const std::string& why, std::string* refusal);
  bool take_announcement(const FederationMessage& message, Nanos now, std::string* refusal);
  // The ids, the writer and the room for a new gateway, before decoding: the reason, or empty.
  std::string cheap_refusal(const FederationMessage& message);
  PeerRecord* by_source(const std::string& source);

  std::uint64_t self_;
  std::size_t max_peers_;
  std::map<std::uint64_t, PeerRecord> peers_;
  std::map<std::uint64_t, FederationMessage> pending_;  // takeovers waiting for the old writer to go
  FederationCounters counters_;
};

}  // namespace cosmic

// This gateway as a member of a federation (gateway.federation, docs/federation.md): follows the
// configuration (joins, rejoins on a changed segment or lease, leaves), announces the gateway's
// state when it changes, applies what the other gateways announce to the gateway's admission
// (Gateway::set_peer_reservations) and logs who joined, left or was lost, and (once per writer) an
// authenticated gateway that gateway.federation.peers does not list.
//
// Threads: the control thread only (tick() from the daemon's loop, peers_json() from the control
// protocol, snapshot() for /metrics); the link's own threads only queue messages for it.
#pragma once

#include <functional>
#include <memory>
#include <set>
#include <nlohmann/json.hpp>

#include "cosmic/federation_link.hpp"
#include "cosmic/federation_view.hpp"
#include "cosmic/gateway.hpp"

namespace cosmicd {

using FederationLinkFactory = std::function<std::unique_ptr<cosmic::FederationLink>(
    const cosmic::SegmentSpec& segment, const cosmic::GatewayIdentity& self, const cosmic::FederationSpec& federation,
    cosmic::Logger& log)>;

struct FederationSnapshot {
  bool enabled = false;
  std::string segment;
  bool secure = false;  // the federation segment has DDS Security
  struct Peer {
    std::string id;
    std::string name;
    std::string state;
    std::string subject;  // authenticated (secure segment), else empty
    double last_heard_age_seconds = 0;
    std::uint64_t revision = 0;
    std::size_t channels = 0;
  };
  std::vector<Peer> peers;
  cosmic::FederationCounters view;
  cosmic::FederationLinkCounters link;
};

class FederationMember {
 public:
  FederationMember(cosmic::Gateway& gateway, cosmic::Logger& log, FederationLinkFactory factory);
  ~FederationMember();

  // Control thread, every tick of the daemon's loop.
  void tick(cosmic::Nanos now);
  // Withdraws this gateway's announcement (peers release its reservations at once) and closes the
  // link. A bind waiting in its claim window is dropped unanswered (the daemon is stopping).
  void leave();

  // The control protocol's BindGate: a plan that adds load to a network an alive peer attaches is
  // announced as a claim and committed after gateway.federation.claim_window (at the first tick
  // after it), against what the others reserve and claim by then; any other plan at once.
  void gate(const cosmic::BindPlan& plan, std::function<void()> commit);

  // The answer of the control command `peers` (docs/control-protocol.md).
  nlohmann::json peers_json(cosmic::Nanos now) const;
  FederationSnapshot snapshot(cosmic::Nanos now) const;

 private:
  void follow_configuration();
  void hear(cosmic::Nanos now);
  void announce();
  void log_transitions(const std::map<std::uint64_t, cosmic::PeerState>& before);
  void log_verdict_changes(const cosmic::AdmissionReport& was, const cosmic::AdmissionReport& now);
  bool touches_shared_network(const cosmic::BindPlan& plan) const;
  void end_claim();  // commits the bind waiting in its claim window

  cosmic::Gateway& gateway_;
  cosmic::Logger& log_;
  FederationLinkFactory factory_;
  // What the running link was made for; an empty segment name when off.
  cosmic::FederationSpec spec_;
  cosmic::SegmentSpec segment_;
  std::string start_error_;  // the last failure to join, logged once
  std::unique_ptr<cosmic::FederationLink> link_;
  std::unique_ptr<cosmic::FederationView> view_;
  std::uint64_t revision_ = 0;
  std::optional<cosmic::Announcement> announced_;  // with revision 0, to compare
  std::uint64_t announced_generation_ = UINT64_MAX;
  bool peers_changed_ = false;
  std::set<std::string> announced_violated_;  // channels announced violated at run time
  struct Claim {
    cosmic::Nanos deadline{0};
    std::function<void()> commit;
    std::vector<cosmic::AnnouncedSegment> segments;  // what this gateway will reserve once committed
  };
  std::optional<Claim> claim_;
  std::uint64_t refusals_logged_ = 0;
  // Writers whose announcements the link refuses (an unlisted gateway): each logged once.
  std::set<std::string> refused_writers_logged_;
};

}  // namespace cosmicd

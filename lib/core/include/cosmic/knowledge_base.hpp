// The knowledge base: what each attached network can deliver (declared properties and live
// health) and every channel reservation on it. Binding is incremental: a channel is admitted only
// if the whole set stays acceptable; a newcomer never breaks an admitted HRT channel, and a
// rejected channel changes nothing.
//
// Binding costs what the newcomer can change (see AdmissionSet): an IP-only channel O(hops + log n),
// a CAN channel the re-analysis of its bus from its priority down. Unbinding keeps every remaining
// CAN channel's priority (see AdmissionSet::remove) and costs O(bound channels).
//
// Not thread-safe: one owner (the daemon's control thread, or cosmicctl check) calls it. A copy is
// independent of the original (plain values, no sharing) and costs O(bound channels + hops): the
// specs with their strings, per-hop places and CAN plans, the last run of each CAN bus, and the
// etag and subject indexes. Measured in tests/bench/admission_bench.cpp (README "Admission at
// scale"): a few milliseconds for 11,000 channels.
#pragma once

#include <cstdint>
#include <optional>
#include <bitset>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/can_wire.hpp"
#include "cosmic/model.hpp"
#include "cosmic/network_identity.hpp"
#include "cosmic/result.hpp"
#include "cosmic/upstream_path.hpp"

namespace cosmic {

enum class SegmentHealth { up, degraded, down };
const char* to_string(SegmentHealth value);

struct SegmentState {
  SegmentSpec spec;
  SegmentHealth health = SegmentHealth::up;
  std::string health_detail;
};

// What the other gateways of a federation reserve on one network (docs/federation.md).
struct PeerReservations {
  double bits_per_second = 0;              // DDS and LCM: the bandwidth their channels reserve
  std::vector<CanBackgroundFrame> frames;  // CAN: their frames, analysed like background frames
  // Channels they send onto the network: a channel of this gateway with the same subject that it
  // receives from there is admitted over the whole path (cosmic/upstream_path.hpp).
  std::vector<UpstreamPath> senders;
  friend bool operator==(const PeerReservations&, const PeerReservations&) = default;
};
// By network identity (cosmic/network_identity.hpp).
using PeerNetworks = std::map<std::string, PeerReservations>;

struct BindOutcome {
  ChannelReport report;  // the channel's verdict with its numbers
  bool bound() const { return report.verdict != Verdict::rejected; }
};

class KnowledgeBase {
 public:
  // `reserved_etags`: static etags declared anywhere in the configuration (reserved_etags()),
  // never handed out dynamically even while their channel is not bound. The etag bits of the
  // segments' extended background frames are never handed out either: COSMIC devices would read
  // those frames as the channel's.
  KnowledgeBase(GatewaySpec gateway, std::vector<SegmentSpec> segments, std::set<std::uint16_t> reserved_etags = {});

  // Tries to bind `channel` (its segments must exist). On rejection nothing changes.
  // `preferred_etag`: taken when the channel needs a dynamic etag and that one is free. A channel
  // whose definition is replaced keeps its etag this way, so CAN devices that learned it through
  // GET_ETAG keep sending and receiving under it.
  BindOutcome bind(const ChannelSpec& channel, std::optional<std::uint16_t> preferred_etag = std::nullopt);
  // Frees the channel's reservations and etag. False when no such channel is bound.
  bool unbind(const std::string& name);
  // What admission would answer for `channel` on top of the current set, without binding it.
  ChannelReport probe(const ChannelSpec& channel) const;

  void set_health(const std::string& segment, SegmentHealth health, std::string detail);
  // A segment added to the running set (a run-time replay's): known to admission from now on,
  // nothing bound re-analysed (CAN priorities, etags and verdicts stay). The name must be new.
  void add_segment(SegmentSpec segment);
  // Removes a segment no bound channel has a hop on; false (nothing changes) otherwise.
  bool remove_segment(const std::string& name);

  // Replaces what other gateways reserve on the networks this gateway's segments attach (segments
  // are matched by network_identity(); networks no segment attaches are ignored) and analyses the
  // bound set again from scratch with it (as AdmissionSet::whole: a CAN bus's priorities may be
  // spread afresh). Bound channels stay bound: one that no longer passes shows `degraded` with the
  // analysis's reasons (two binds that raced on two gateways), as does one whose etag another
  // gateway's frames on a shared bus carry; newcomers are admitted against it. The etags of the
  // peers' extended frames are never handed out.
  void set_peer_reservations(PeerNetworks peers);
  const PeerNetworks& peer_reservations() const { return peers_; }

  // Verdicts of the bound set (live health applied) and the load of every segment.
  AdmissionReport report() const;
  // The load of every segment and how many hops of bound channels it carries (same order),
  // without building the channels' reports: cheap enough to call every control-loop tick.
  std::vector<SegmentLoad> loads() const { return set_.loads(); }
  std::vector<std::size_t> hop_counts() const { return set_.hop_counts(); }

  const GatewaySpec& gateway() const { return set_.gateway(); }
  const std::vector<SegmentState>& segments() const { return segments_; }
  const std::vector<ChannelSpec>& bound_channels() const { return set_.channels(); }
  const ChannelSpec* find_bound(const std::string& name) const;
  std::optional<std::uint16_t> etag_of(const std::string& channel) const;

 private:
  struct Attempt {
    std::optional<AdmissionSet::Trial> trial;  // nullopt: refused before any analysis
    ChannelReport report;                      // the newcomer's report, including "would break" reasons
    std::optional<std::uint16_t> etag;         // CAN channels: the etag it would take
  };
  Attempt attempt(const ChannelSpec& channel, std::optional<std::uint16_t> preferred_etag = std::nullopt) const;
  std::optional<std::uint16_t> allocate_etag() const;
  bool needs_etag(const ChannelSpec& channel) const;
  Result<void> check_native_identities(const ChannelSpec& channel, std::optional<std::uint16_t> etag) const;

  // The segments as admission sees them: the configured ones plus what other gateways reserve.
  std::vector<SegmentSpec> analysed_segments() const;
  // What other gateways reserve on the network `segment` attaches, or null.
  const PeerReservations* peers_on(const SegmentSpec& segment) const;
  // The path another gateway gives `channel`'s events before a network this gateway receives it
  // from (the slowest, when several do), applied to its report.
  void add_upstream(const ChannelSpec& channel, ChannelReport& report) const;
  // peer_etags_ from what the peers reserve on the CAN segments there are now.
  void collect_peer_etags();

  std::vector<SegmentState> segments_;
  AdmissionSet set_;
  PeerNetworks peers_;
  // Etag bits of other gateways' extended frames on the networks of this gateway's segments, with
  // the name of one frame carrying each.
  std::map<std::uint16_t, std::string> peer_etags_;
  std::set<std::uint16_t> reserved_etags_;
  EtagMap etags_;                                            // bound CAN channels
  std::bitset<kMaxEtag + 1> etag_taken_;                     // reserved or bound: never handed out
  std::unordered_map<std::uint64_t, std::string> subjects_;  // subject -> bound channel
  // Native identities of bound channels: (segment, identity) -> channel, and the etag bits of
  // their extended CAN identifiers (never handed out while such a channel is bound).
  std::map<std::pair<std::string, std::string>, std::string> native_owners_;
  std::multimap<std::uint16_t, std::string> native_etags_;
};

// The etags a configuration reserves: its channels' static etags and the etag bits of their
// native extended CAN identifiers.
std::set<std::uint16_t> reserved_etags(const Config& config);

// Binds every channel of `config` in order and reports the final set; each rejected channel is
// reported as evaluated on top of the final set.
AdmissionReport admit_all(const Config& config);

}  // namespace cosmic

// Admission and QoS-mismatch checks (DESIGN.md section 4) as pure functions.
//
// evaluate() analyses one set of channels as if all of them were bound together: CAN priorities
// (class band, deadline-monotonic inside it), frame times, worst-case response times with a
// holistic jitter iteration across gateway hops, bandwidth, latency budget, validity, omission
// and real-time capability. AdmissionSet keeps that analysis between binds and gives, for a
// newcomer, exactly what evaluate() would give for the whole set while re-examining only what the
// newcomer can change. The policy (a newcomer never breaks an admitted HRT channel) lives in
// KnowledgeBase.
#pragma once

#include <cstdint>
#include <map>
#include <unordered_map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosmic/can_background.hpp"
#include "cosmic/can_timing.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/model.hpp"

namespace cosmic {

// Admission answers bound, degraded or rejected. `failed` is never admission's answer: the
// gateway gives it to an admitted channel that a segment's transport refused to carry
// (SegmentAdapter::configure), with the transport's reason; its reservations stay held.
enum class Verdict { bound, degraded, rejected, failed };
enum class HopRole { publisher, subscriber };

const char* to_string(Verdict value);
const char* to_string(HopRole value);

// One criterion's number against its limit. `relation` is how value must compare to limit
// ("<=", "<", ">="); ok says whether it does.
struct Check {
  // frame_fit, utilization, response_time, latency, omission, realtime, representation, range,
  // authentication, replay_events, replay_rate, fmu_rate, fmu_validity
  std::string check;
  double value = 0;
  double limit = 0;
  std::string unit;  // "s", "B", "ratio", "events", "bool"
  std::string relation;
  bool ok = true;
};

// A CAN hop as it is on the wire, in the segment's profile (docs/can-wire-format.md):
// - cosmic: can_id = priority (8 bits) | TxNode | etag; the gateway's TxNode on both roles.
// - famouso: can_id = priority (7 bits) | fragment flag | TxNode | etag. Subscriber hops (the
//   gateway sends): the planned priority in 7 bits, the gateway's TxNode, the fragment flag when
//   the channel's events need AFP fragments. Publisher hops (FAMOUSO nodes send): their fixed
//   priority 0x7D and the last TxNode the CCP broker assigns (0x7E).
// The response-time analysis orders the streams by can_id, so it sees the arbitration the bus does.
struct CanHopPlan {
  CanProfile profile = CanProfile::cosmic;
  // A native channel (ChannelSpec::native): its fixed identifier, standard or extended; no etag,
  // priority field or fragmentation.
  bool native = false;
  bool extended = true;
  std::uint8_t priority = 0;  // the identifier's priority field (7 bits in the FAMOUSO profile)
  std::uint32_t can_id = 0;   // 29-bit identifier of the hop's frames
  std::uint16_t etag = 0;
  std::uint32_t frame_bytes = 0;       // data bytes of one frame (FD: padded length)
  std::uint32_t frames_per_event = 1;  // > 1 for fragmented NRT events
  Nanos transmission{0};               // worst-case time of one frame
  Nanos jitter{0};                     // release jitter used in the analysis
  std::optional<Nanos> response_time;  // nullopt: unbounded
  friend bool operator==(const CanHopPlan&, const CanHopPlan&) = default;
};

// The plan's identifier as the bus orders it (standard and extended identifiers compared the way
// arbitration does).
inline std::uint32_t arbitration_key(const CanHopPlan& plan) {
  return arbitration_key(plan.can_id, plan.extended ? CanIdFormat::extended29 : CanIdFormat::standard11);
}

// What DDS Security's AES-GCM-GMAC transformations add to one sample at most (DDS Security 1.1,
// section 9.5.3): the payload's (CryptoHeader 20 B, the body's length 4 B, CryptoFooter 20 B), the
// submessage's (SEC_PREFIX 24 B, SEC_BODY header and length 8 B, SEC_POSTFIX 24 B) and the RTPS
// message's (SRTPS_PREFIX 24 B, SEC_BODY 8 B, SRTPS_POSTFIX 24 B), with no receiver-specific MACs.
// A governance that protects less adds less; admission counts the bound.
inline constexpr std::size_t kDdsSecurityMaxOverheadBytes = 44 + 56 + 56;

// What authentication adds on a hop (docs/security.md): the scheme and the bytes it adds to each
// message (LCM, DDS) or frame (CAN), which the hop's size and load checks count.
struct HopSecurity {
  std::string scheme;       // "HMAC-SHA256 trailer"
  std::uint32_t bytes = 0;  // added to each message or frame
  // What its cryptography adds to the hop's latency, as measured (`cosmicctl calibrate`) and
  // configured; none when not configured (then not counted).
  std::optional<Nanos> time{};
  friend bool operator==(const HopSecurity&, const HopSecurity&) = default;
};

struct HopReport {
  std::string segment;
  HopRole role = HopRole::publisher;
  std::optional<CanHopPlan> can;
  std::optional<DdsTopicRef> dds;  // DDS hops: the topic and type the channel travels as
  std::optional<Nanos> latency;    // worst-case latency this hop adds; nullopt: unbounded
  std::vector<Check> checks;
  // CAN hops whose response time misses the reaction time: the background frames delaying it most.
  std::vector<BackgroundDelay> background;
  // A typed channel's hop: the form its events take there ("DBC frame 0x1A0 WheelSpeed", "XCDR2",
  // "compact"; ChannelSpec::hop_payloads), empty when the hop cannot carry the type.
  std::string representation;
  std::optional<HopSecurity> security{};  // none where the hop is not authenticated
};

// A hop of a channel's path on another gateway of the federation (cosmic/upstream_path.hpp).
struct PathHop {
  std::string gateway;  // that gateway's name
  std::string segment;  // its name for the segment
  HopRole role = HopRole::publisher;
  std::optional<Nanos> latency;  // nullopt: unbounded
  std::uint64_t gateway_id = 0;  // its GatewayIdentity::id: a path through the reader itself is a ring
  friend bool operator==(const PathHop&, const PathHop&) = default;
};

struct EndToEnd {
  // P hop + gateway residence + S hop, worst pair; nullopt: unbounded. For a channel whose events
  // reach this gateway through other gateways (`upstream`), the whole path: their age on arrival
  // plus this gateway's part (`local`).
  std::optional<Nanos> latency;
  std::optional<Nanos> upstream{Nanos(0)};  // age of the events when they reach this gateway's P network
  std::optional<Nanos> local;               // this gateway's part, when there is an upstream path
  std::optional<Nanos> reaction_time;
  std::optional<Nanos> temp_validity;
  bool latency_ok = true;
  bool validity_ok = true;
  bool ok() const { return latency_ok && validity_ok; }
};

struct ChannelReport {
  std::string name;
  ChannelClass cls = ChannelClass::nrt;
  Verdict verdict = Verdict::bound;
  std::vector<std::string> reasons;
  std::vector<HopReport> hops;
  // The hops on other gateways before this one's, in path order (empty: the events start here),
  // and then this gateway's name for its own hops.
  std::vector<PathHop> upstream;
  std::string gateway;
  EndToEnd end_to_end;
};

// How a failing criterion ("frame_fit", "latency", ...) affects the verdict of a channel of `cls`:
// rejected for HRT channels, for a frame that does not fit, for a hop whose representation
// cannot carry the channel's type ("representation") and for an FMU that would publish faster than
// the period ("fmu_rate"), degraded otherwise (e.g. "range": the hop saturates values of a field's
// declared range; "fmu_validity": an FMU's step is longer than temp_validity).
Verdict consequence_of(const std::string& check, ChannelClass cls);

// A rejection of `channel` for one reason, before any hop is judged (already bound, not bound
// where a replacement needs it, no etag left, ...).
ChannelReport rejected_report(const ChannelSpec& channel, std::string reason);

struct SegmentLoad {
  std::string name;
  SegmentType type = SegmentType::dds;
  double utilization = 0;  // everything the bus carries: the bound channels plus the background
  double max_utilization = 0;
  double background = 0;  // CAN: the other devices' frames (segment key `background`), other gateways' included
  std::size_t background_frames = 0;
  double peers = 0;  // what other gateways of the federation reserve (SegmentSpec::peer_load)
};

struct AdmissionReport {
  std::vector<SegmentLoad> segments;
  std::vector<ChannelReport> channels;  // bound and degraded first in bind order, then rejected
  bool any_rejected() const;
  const ChannelReport* find(const std::string& name) const;
};

// Etag of every channel that touches a CAN segment.
using EtagMap = std::map<std::string, std::uint16_t>;

// Bytes an event occupies on an IP segment beyond its payload (envelope + transport headers):
// used for bandwidth and message-size checks.
inline constexpr std::uint64_t kIpOverheadBytes = 96;

// What authentication adds to each of `channel`'s messages or frames on `segment`; nullopt where
// the hop is not authenticated (an LCM segment without auth, ...).
std::optional<HopSecurity> hop_security(const SegmentSpec& segment, const ChannelSpec& channel);
// What a CAN hop's SecOC adds to its latency (its `cost`); zero without SecOC or cost.
Nanos can_hop_security_cost(const SegmentSpec& segment, const ChannelSpec& channel);
// The latency an IP segment's hop promises: the segment's latency_bound, and what its
// authentication's cryptography costs where that is configured.
Nanos ip_hop_latency(const SegmentSpec& segment);

struct Evaluation {
  std::vector<ChannelReport> channels;  // same order as the input
  std::vector<SegmentLoad> segments;    // same order as the segments
};

// Analyses `channels` bound together on `segments`. Channel names must refer to existing
// segments (the configuration layer guarantees it).
Evaluation evaluate(const GatewaySpec& gateway, std::span<const SegmentSpec> segments,
                    std::span<const ChannelSpec> channels, const EtagMap& etags);

// A bound set with its analysis kept between binds.
//
// trial() analyses a newcomer on top of the set and answers exactly what evaluate() answers for
// the whole set plus the newcomer, at the cost of what the newcomer can change:
// - a channel on IP segments only: its own hops and the load of its segments, O(hops);
// - a channel on a CAN bus: that bus's priorities (O(n log n)), the response times of the streams
//   of equal or lower priority (higher ones only if its frame lengthens their blocking, and the
//   whole band when more channels than priority levels re-spread it), and, through the holistic
//   jitter iteration, the CAN hops downstream of the changed ones. IP-only channels are not
//   visited.
// remove() keeps every remaining CAN hop's priority and identifier (see remove()); while no
// removal happened, every result equals evaluate()'s.
//
// Copy: O(channels + hops): the specs (strings), each hop's place, each CAN hop's plan and the
// last analysis of each CAN bus; no shared state, so a copy can be analysed on another thread.
// Not thread-safe: one owner at a time.
class AdmissionSet {
 public:
  AdmissionSet(GatewaySpec gateway, std::vector<SegmentSpec> segments);
  // The set of `channels` bound together (etags by channel name, 0 when absent), analysed as a
  // whole: what evaluate() reports.
  static AdmissionSet whole(GatewaySpec gateway, std::vector<SegmentSpec> segments,
                            std::span<const ChannelSpec> channels, const EtagMap& etags);

 private:
  struct HopPlace {
    std::size_t segment;
    std::size_t position;  // index in that segment's hop list
    HopRole role;
  };
  struct ChannelData {
    std::uint16_t etag = 0;
    std::vector<HopPlace> places;  // publishers then subscribers, as in the spec
  };
  struct HopRef {
    std::size_t channel;
    std::size_t hop;
  };
  struct Segment {
    std::vector<HopRef> hops;           // bind order
    double load = 0.0;                  // background_load plus the bound channels' hops
    std::vector<CanStream> background;  // CAN: the background frames as streams, fixed with the spec
    double background_load = 0.0;
    std::vector<CanHopPlan> plans;     // CAN: one per hop, same order
    std::vector<CanBusAnalysis> runs;  // CAN: one per jitter iteration of the last analysis
    bool pinned = false;               // CAN: priorities kept over a removal, not those a fresh plan gives
  };
  struct CanSide {
    std::vector<bool> replanned;                 // by segment: priorities planned afresh
    std::vector<std::vector<CanHopPlan>> plans;  // by segment
    std::vector<std::vector<CanBusAnalysis>> runs;
    bool diverged = false;  // no jitter fixed point: subscriber-side CAN hops unbounded
  };

 public:
  // A newcomer analysed on top of the set; commit() binds it as analysed.
  struct Trial {
    ChannelReport report;                   // the newcomer in the new set
    std::vector<ChannelReport> broken_hrt;  // bound HRT channels the newcomer would reject, bind order
    // Background frames with a deadline (other gateways' HRT frames) that met it and would not.
    struct BrokenFrame {
      std::string name;               // e.g. "gw1:steer"
      std::string origin;             // e.g. "gateway gw1 (00000000000010ab)"
      std::optional<Nanos> response;  // nullopt: unbounded
      Nanos deadline{0};
    };
    std::vector<BrokenFrame> broken_frames;

   private:
    friend class AdmissionSet;
    ChannelSpec spec;
    ChannelData data;
    std::vector<std::pair<std::size_t, double>> loads;  // touched segments
    std::optional<CanSide> can;                         // nullopt: the CAN side is unchanged
  };
  Trial trial(const ChannelSpec& channel, std::uint16_t etag) const;
  void commit(Trial trial);

  // Removes a bound channel. Every remaining CAN hop keeps its priority and identifier: with
  // more channels than priority levels in a band, re-spreading the band could put a channel
  // level with one that wins arbitration over it and break an admitted HRT guarantee. With
  // priorities kept, every remaining response time, load and latency can only shrink. The next
  // bind onto that bus plans it afresh and re-checks every admitted HRT channel (so it may be
  // refused as "would break"); binds elsewhere leave it as it is. Until then the set differs from
  // what evaluate() gives for the same channels, by design. False when not bound.
  bool remove(const std::string& name);
  // A segment added after the others (a run-time replay's), carrying nothing yet: no analysis
  // changes, every bound channel keeps its plan (a CAN bus its pinned priorities).
  void add_segment(SegmentSpec segment);
  // Removes a segment no bound channel has a hop on; false (nothing changes) otherwise or when
  // there is no such segment. The others keep their analysis.
  bool remove_segment(const std::string& name);

  const std::vector<ChannelSpec>& channels() const { return specs_; }
  const ChannelSpec* find(const std::string& name) const;
  std::vector<ChannelReport> reports() const;  // bind order
  std::vector<SegmentLoad> loads() const;      // segment order
  // How many hops of bound channels each segment carries, in segment order (no reports built).
  std::vector<std::size_t> hop_counts() const;
  const std::vector<SegmentSpec>& segment_specs() const { return segment_specs_; }
  const GatewaySpec& gateway() const { return gateway_; }

 private:
  ChannelData place(const ChannelSpec& channel, std::uint16_t etag) const;
  void append(ChannelSpec spec, ChannelData data);
  std::vector<CanHopPlan> plan_bus(std::size_t segment, const Trial* newcomer) const;
  CanSide analyse_can(const Trial* newcomer, bool replan_all) const;
  ChannelReport report_of(const ChannelSpec& spec, const ChannelData& data, const Trial* change) const;
  std::vector<std::size_t> affected_by(const Trial& t) const;
  std::vector<Trial::BrokenFrame> frames_broken_by(const CanSide& side) const;
  struct Member {
    const ChannelSpec* spec;
    const ChannelData* data;
    HopRole role;
  };
  Member member(std::size_t segment, std::size_t position, const Trial* newcomer) const;
  bool update_jitters(CanSide& side, const Trial* newcomer) const;
  void apply(CanSide side);
  // What segment `s` carries before any channel is bound (its background), from its spec.
  void init_segment(std::size_t s);

  GatewaySpec gateway_;
  std::vector<SegmentSpec> segment_specs_;
  std::vector<Segment> segments_;
  std::vector<ChannelSpec> specs_;  // bind order
  std::vector<ChannelData> data_;   // same order
  std::unordered_map<std::string, std::size_t> index_;
  bool diverged_ = false;
};

}  // namespace cosmic

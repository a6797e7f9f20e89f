// The running gateway: the knowledge base, one adapter per segment, the router and its thread,
// and the binding operations (start, bind, unbind, reload) that keep the three consistent.
//
// Threads: every public method is called by the one control thread; the router's egress lanes
// run their own threads (started per segment); adapters run their own receive threads.
//
// Runtime verification: refresh_runtime() compares what the lanes measured with what admission
// promised. An HRT channel whose hop missed gateway.residence_bound or its reaction_time becomes
// `violated` (logged once per episode at warning, with the numbers) and returns to `bound` after
// gateway.clean_interval without a miss.
//
// Transport refusals: when a segment's adapter does not take a channel (configure() fails, at
// start, bind, unbind or reload), the channel's verdict is `failed` with the adapter's reason in
// admission(), in the BindResult and in one error log line naming the channel and the segment
// (repeated only when the reason changes). A bind whose own channels are refused changes
// nothing; at start and reload the channel stays admitted (its reservations held, so the next
// configuration, e.g. a reload, tries again) and the rest runs.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/knowledge_base.hpp"
#include "cosmic/log.hpp"
#include "cosmic/router.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

using AdapterFactory = std::function<std::unique_ptr<SegmentAdapter>(const SegmentSpec& segment,
                                                                     const GatewayIdentity& self, Logger& log)>;

// A channel whose definition a replacement takes the place of.
struct ReplacedChannel {
  ChannelSpec before;                // the definition bound before
  std::vector<std::string> changes;  // one line per field the new definition changes (channel_changes.hpp)
};

// A publisher hop a replacement adds, opened before the switch (make before break).
struct NewPublisher {
  std::string channel;
  std::string segment;
  // Remote writers its endpoint had matched at the switch; nullopt where the transport has no
  // discovery (LCM, CAN: whatever is sent there is received as soon as the hop exists).
  std::optional<std::size_t> matched;
};

struct BindResult {
  bool applied = false;                 // false: nothing changed
  std::vector<ChannelReport> channels;  // verdict of each requested channel
  std::string error;                    // why nothing changed, when not a rejection
  // A replacement: the channels it concerns that were bound, in the order of `channels`.
  std::vector<ReplacedChannel> replaced;
  // A replacement, made before break: its new publisher hops as they were at the switch, how long
  // the switch waited for them to match after they were opened, and whether it gave up waiting.
  std::vector<NewPublisher> new_publishers;
  Nanos switch_wait{0};
  bool match_timed_out = false;
};

struct SegmentInfo {
  SegmentSpec spec;
  HealthReport health;
  AdapterStatistics adapter;
  double utilization = 0;  // other gateways' reservations included
  double peers = 0;        // what other gateways of the federation reserve here
  std::size_t channels = 0;
  std::uint64_t unrouted = 0;
};

// Admission of a bind, split so a long one can run off the control thread: the plan is pure
// (any thread, on its own copy of the knowledge base), the commit runs on the control thread.
struct BindPlan {
  std::uint64_t generation = 0;  // Gateway::generation() the copy was taken at
  std::vector<ChannelSpec> channels;
  std::shared_ptr<KnowledgeBase> kb;   // the copy; holds `channels` once planned and admitted
  std::vector<ChannelReport> reports;  // verdict of each channel, once planned
  bool admitted = false;               // every channel bound in `kb`
  // A replacement (Gateway::replace): `channels` take the place of the bound definitions of the
  // same names, which are `replaced` (taken with the copy).
  bool replacing = false;
  std::vector<ChannelSpec> replaced;
};

// What the running bindings were admitted from (at start or by the last reload): the
// configuration, its knowledge base right after admission (no live health, no refusals) and the
// verdicts given then. A reload of the same or an extended configuration starts from it.
// Immutable once made.
struct ReloadBase {
  Config config;
  KnowledgeBase kb;
  std::vector<ChannelReport> reports;
};

// The same for a reload: the knowledge base of the new configuration.
struct ReloadPlan {
  Config config;
  std::shared_ptr<KnowledgeBase> kb;
  std::vector<ChannelReport> reports;
  std::size_t reused = 0;                      // channels taken over from the ReloadBase, not admitted again
  std::shared_ptr<const ReloadBase> admitted;  // this plan's admission, for the next reload
};

// The router limits gateway.residence_bound and gateway.realtime ask for (the lanes' priorities
// and CPUs); shared by the gateway and `cosmicctl calibrate`.
RouterLimits router_limits(const GatewaySpec& gateway);

class Gateway {
 public:
  static constexpr std::size_t kMaxSegments = 64;

  Gateway(AdapterFactory factory, Logger& log, std::uint64_t gateway_id);
  ~Gateway();
  Gateway(const Gateway&) = delete;
  Gateway& operator=(const Gateway&) = delete;

  // Creates and starts the adapters, binds every channel through admission (rejected ones are
  // reported and left unbound), starts the router thread. Fails only when an adapter cannot be
  // created; segments that start but are unhealthy are reported by health.
  BindResult start(const Config& config);
  // Binds the channels together, or none of them when any is rejected.
  BindResult bind(const std::vector<ChannelSpec>& channels);
  // Replaces the definitions of bound channels (cosmicctl bind --replace): admission runs once on
  // the bound set less the replaced channels plus their new definitions; when any is rejected (or
  // not bound) nothing changes. A replaced channel keeps its channel id, so adapters keep the
  // endpoints of its hops whose segment, role and transport QoS stay, and its etag where it still
  // needs one; events already queued for subscriber segments that stay are still sent.
  // Made before break: the new hops are opened first, beside the running ones, and the switch
  // waits (polling, at most `match_timeout`) until every new publisher hop on a transport with
  // discovery has matched a remote writer; the old publishers feed the channel until then.
  BindResult replace(const std::vector<ChannelSpec>& channels, Nanos match_timeout = kDefaultMatchTimeout);
  static constexpr Nanos kDefaultMatchTimeout{5'000'000'000};
  // False when no such channel is bound.
  bool unbind(const std::string& name);
  // Validated configuration in, running one swapped: unchanged segments and channels keep
  // flowing. On failure the running configuration stays untouched.
  BindResult reload(const Config& config);

  // bind() in steps. Control thread: the plan's input (a copy of the knowledge base).
  BindPlan bind_plan_input(std::vector<ChannelSpec> channels) const;
  // Any thread, no I/O: admission of plan.channels on plan.kb.
  static void plan_bind(BindPlan& plan);
  // Control thread: applies an admitted plan. Refused (nothing changes) when the bindings
  // changed since the plan's copy was taken.
  BindResult commit_bind(BindPlan plan);
  // replace() in the same steps; commit_bind() commits either kind of plan.
  BindPlan replace_plan_input(std::vector<ChannelSpec> channels) const;
  static void plan_replace(BindPlan& plan);
  // Make before break, control thread. prepare_replace() opens an admitted replacement's hops on
  // segments the channel does not use yet, beside the running ones; routes stay as they are (the
  // old publishers keep feeding the channel; what reaches a new publisher hop before the switch
  // counts as no_route). False when there is nothing to wait for: not admitted, bindings changed
  // since the plan, no such hop, or a segment refused one (then closed again: the commit reports
  // it). switch_over() then commits (commit_bind), closing the opened hops when the commit refuses,
  // and says how long the switch waited and what the new publishers had matched.
  bool prepare_replace(const BindPlan& plan);
  BindResult switch_over(BindPlan plan, std::chrono::steady_clock::time_point prepared_at, bool timed_out);
  // The new publisher hops of a replacement with the remote writers each has matched now.
  std::vector<NewPublisher> new_publishers(const BindPlan& plan) const;
  // Blocks, polling, until all_matched() or `match_timeout` after `prepared_at`; false at the timeout.
  bool await_new_publishers(const BindPlan& plan, std::chrono::steady_clock::time_point prepared_at,
                            Nanos match_timeout) const;
  // True when every new publisher hop on a transport with discovery has matched a writer.
  static bool all_matched(const std::vector<NewPublisher>& publishers);
  // reload() in steps: the plan on any thread (no I/O), the commit on the control thread.
  // With `base` (reload_base(), taken on the control thread) a configuration with the base's
  // gateway, segments and reserved etags whose channels begin with the base's, in order, starts
  // from the base's admission and admits only the channels after them: an unchanged file is not
  // admitted again. The plan is the one admission from scratch gives (binding is incremental and
  // deterministic); any other configuration is admitted from scratch.
  // `peers`: what other gateways reserve (knowledge_base().peer_reservations(), copied on the
  // control thread), counted by the new configuration's admission.
  static ReloadPlan plan_reload(Config config, std::shared_ptr<const ReloadBase> base = nullptr,
                                PeerNetworks peers = {});
  BindResult commit_reload(ReloadPlan plan);
  // Control thread: what the running bindings were admitted from; null once a bind or unbind
  // changed them since start or the last reload.
  std::shared_ptr<const ReloadBase> reload_base() const;
  // Control thread: admission's report of a channel of the loaded configuration (start or the last
  // reload) that admission rejected then and that is not bound now; null otherwise.
  const ChannelReport* rejected_at_load(const std::string& name) const;
  // A segment added to the running gateway (cosmicctl replay, control thread): its adapter created
  // and started, the knowledge base told of it without analysing anything bound again (verdicts,
  // etags and CAN priorities stay). Nothing changes when the name is taken, no slot is free or the adapter cannot be
  // made. The segment carries no channel until a bind or replacement names it; a reload whose file does not name it
  // removes it. Changes generation().
  Result<void> add_segment(const SegmentSpec& segment);
  // Removes a segment add_segment() added, or any other, once no bound channel has a hop on it.
  Result<void> remove_segment(const std::string& name);
  // Changes with every applied bind, unbind and reload.
  std::uint64_t generation() const { return generation_; }
  void stop();

  // What other gateways of the federation reserve, by network (FederationView::reservations):
  // admission counts it from now on on the segments attaching those networks, the bound set is
  // analysed again with it, and a bind whose admission ran meanwhile is refused ("try again").
  // Kept across reloads (a renamed segment on the same network keeps them).
  void set_peer_reservations(PeerNetworks peers);

  // Reads adapter health into the knowledge base (call periodically).
  void refresh_health();
  // Updates the runtime state of every channel from the lanes' miss counters (call periodically).
  void refresh_runtime(Nanos now);
  // Channels whose bounds do not hold now for a reason reported from outside the gateway, by name,
  // with the reason (an FMU's runner reporting a worst step beyond its step, cosmic/fmu_reports.hpp).
  // Each such bound channel, whatever its class, is judged violated at every refresh_runtime() as
  // for a miss (the reason logged when the episode begins) until it is no longer named and a clean
  // interval passed. Replaces the previous set. Control thread.
  void set_reported_violations(std::map<std::string, std::string> reasons) { reported_ = std::move(reasons); }
  std::size_t violated_channels() const;
  // Their names (the federation announces them to gateways downstream).
  std::set<std::string> violated_channel_names() const;
  // What the forwarding threads could not get of gateway.realtime since the last call.
  std::vector<std::string> take_thread_problems();
  // The form a routed typed channel's events take on `segment` ("DBC frame 0x1A0 WheelSpeed",
  // "compact", "JSON", "XCDR1"); nullopt for an untyped or unrouted channel. Control thread.
  std::optional<std::string> hop_form(const std::string& channel, const std::string& segment) const;

  const GatewayIdentity& identity() const { return identity_; }
  const Config& config() const { return config_; }
  const KnowledgeBase& knowledge_base() const { return *kb_; }
  // Verdicts of the bound channels: admission's, or `failed` where a segment refused the channel.
  AdmissionReport admission() const;
  // How many bound channels admission() shows bound, degraded and failed (it builds every report:
  // milliseconds at ten thousand channels).
  struct VerdictCounts {
    std::size_t bound = 0;
    std::size_t degraded = 0;
    std::size_t failed = 0;
  };
  VerdictCounts verdict_counts() const;
  std::vector<SegmentInfo> segments() const;
  // The router's counters plus each channel's runtime state.
  std::vector<ChannelStatsSnapshot> channel_stats() const;
  const Router& router() const { return *router_; }
  bool all_segments_up() const;
  // Discovered remote endpoints of a bound channel on a segment (see SegmentAdapter).
  std::optional<std::size_t> matched_peers(const std::string& segment, const std::string& channel) const;
  // Remote endpoints of a bound channel refused on a segment for incompatible QoS (see SegmentAdapter).
  std::optional<std::uint64_t> incompatible_peers(const std::string& segment, const std::string& channel) const;
  // Remote endpoints of a bound channel on a segment that the far side refuses by rules the
  // transport does not report (see SegmentAdapter::peer_qos_conflicts).
  std::vector<PeerQosConflict> peer_qos_conflicts(const std::string& segment, const std::string& channel) const;

  // Taps on a bound channel's admitted events (cosmicctl echo; cosmic/channel_tap.hpp): a tap on
  // the channel as it is bound now (a replacement's events go to a new tap), or why not.
  Result<std::uint32_t> open_tap(const std::string& channel);
  std::optional<TapRead> read_tap(std::uint32_t tap);
  void close_tap(std::uint32_t tap);

  // The recorder (issue 37; cosmic/record_hook.hpp): `hook` sees the admitted events of the
  // channels `selects` picks, in this route table and every later one, and `on_routes` is shown
  // each route table as applied (start, bind, unbind, reload). The hook must outlive the gateway's
  // router. select_recorded() changes only the selection (recording started or stopped).
  using RouteObserver = std::function<void(const std::vector<Route>&)>;
  void set_recording(RecordHook* hook, std::function<bool(const ChannelSpec&)> selects, RouteObserver on_routes);
  void select_recorded(std::function<bool(const ChannelSpec&)> selects);

 private:
  struct SegmentSlot {
    std::size_t index = 0;
    SegmentSpec spec;
    std::unique_ptr<SegmentAdapter> adapter;
    // Bindings (channel id, role) the adapter is known to carry: all it was given at its last
    // successful configure(), less what it refused since.
    std::set<std::pair<ChannelId, HopRole>> carried;
  };
  // Channel name -> segment name -> the transport's reason for not carrying it.
  using Refusals = std::map<std::string, std::map<std::string, std::string>>;

  struct RuntimeTrack {
    RuntimeState state = RuntimeState::bound;
    std::uint64_t misses = 0;           // residence + deadline misses seen at the last refresh
    std::uint64_t omission_excess = 0;  // gaps beyond the omission degree seen at the last refresh
    Nanos last_miss{0};
    std::uint64_t violations = 0;
  };

  // Configures every adapter with the bound set plus `extra` (segment name -> a binding of a
  // replacement being prepared); returns (and keeps in refused_) what they refused.
  Refusals configure_adapters(const std::multimap<std::string, ChannelBinding>& extra = {});
  // commit_bind() without closing what prepare_replace() opened when it refuses.
  BindResult commit_plan(BindPlan plan);
  // The hops of `plan`'s new definitions that the running bindings do not have, by segment.
  std::multimap<std::string, ChannelBinding> added_hops(const BindPlan& plan) const;
  // Makes `report` say `failed`, with the reasons, when a segment refused its channel.
  void mark_refused(ChannelReport& report) const;
  // `foreign`: why the channel's analysis does not hold now (undeclared frames beat it), or null.
  // `reported`: why its bounds do not hold by a report from outside (set_reported_violations), or null.
  void judge(const ChannelMisses& counted, const ChannelSpec& spec, RuntimeTrack& track, Nanos now,
             const std::string* foreign, const std::string* reported);
  // HRT channels that frames unknown to admission beat on a CAN bus: name -> reason.
  std::map<std::string, std::string> undeclared_interference() const;
  std::string violation_line(const ChannelSpec& spec) const;
  std::string omission_line(const ChannelSpec& spec) const;
  void apply_routes();
  bool add_representations(Route& route);
  ChannelId id_for(const ChannelSpec& spec);
  // A replacement's new definitions take over their channels' ids; returns the entries they
  // replaced, for undo_takeover().
  std::map<std::string, std::pair<ChannelSpec, ChannelId>> take_over_ids(const std::vector<ChannelSpec>& channels);
  void undo_takeover(std::map<std::string, std::pair<ChannelSpec, ChannelId>>&& previous);
  // Lowest slot index used neither by a running segment nor by one in `also_taken`.
  std::size_t free_slot(const std::set<std::size_t>& also_taken = {}) const;
  static std::unique_ptr<KnowledgeBase> knowledge_base_for(const Config& config);

  AdapterFactory factory_;
  Logger& log_;
  GatewayIdentity identity_;
  Config config_;
  std::unique_ptr<KnowledgeBase> kb_;
  std::unique_ptr<Router> router_;
  std::map<std::string, RuntimeTrack> runtime_;  // by channel name
  std::map<std::string, std::string> reported_;  // set_reported_violations(): channel -> reason
  RecordHook* record_hook_ = nullptr;
  std::function<bool(const ChannelSpec&)> record_selection_;
  RouteObserver on_routes_;
  // What each routed typed channel's hops carry (Representation::describe()), as apply_routes() built
  // them: channel -> segment -> form.
  std::map<std::string, std::map<std::string, std::string>> hop_forms_;
  Refusals refused_;                          // after the last configure_adapters()
  std::map<std::string, SegmentSlot> slots_;  // by segment name
  std::map<std::string, std::pair<ChannelSpec, ChannelId>> channel_ids_;
  ChannelId next_channel_id_ = 1;
  std::uint64_t generation_ = 0;
  bool prepared_ = false;                   // adapters carry a replacement's added hops (prepare_replace)
  std::shared_ptr<const ReloadBase> base_;  // valid while generation_ == base_generation_
  std::uint64_t base_generation_ = 0;
};

}  // namespace cosmic

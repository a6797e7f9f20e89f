// The control protocol of cosmicd (docs/control-protocol.md): one JSON object per line in each
// direction over a Unix stream socket. This part turns a request line into a response line; it
// does no I/O of its own. Called by the control thread only; the admission of a bind or reload
// may run on a worker thread (see Offload), and its answer then comes back on the control thread.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "cosmic/denial_log.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/fmu_reports.hpp"
#include "cosmic/gateway.hpp"

namespace cosmic {

// Who is asking (from SO_PEERCRED).
struct PeerCredentials {
  int pid = -1;
  unsigned uid = 0;
  unsigned gid = 0;
};

// Decides whether a peer may run a command class; installed by the daemon. `may_report`: send
// fmu_report, a runner's report, which binds nothing but can flag an FMU's output channels violated.
struct AccessPolicy {
  std::function<bool(const PeerCredentials&)> may_read = [](const PeerCredentials&) { return true; };
  std::function<bool(const PeerCredentials&)> may_modify = [](const PeerCredentials&) { return true; };
  std::function<bool(const PeerCredentials&)> may_report = [](const PeerCredentials&) { return true; };
};

// Told about every mutating command that changed the gateway (e.g. to persist it). Returns why
// the change could not be saved, or an empty string; the client then gets `not_persisted`.
using ChangeObserver = std::function<std::string(const std::string& command, const nlohmann::json& request)>;

// Runs `work` away from the control thread, then `done` on the control thread. `work` touches
// only what it was given (a copy of the knowledge base, a configuration being loaded).
using Offload = std::function<void(std::function<void()> work, std::function<void()> done)>;

// Delivers a deferred answer line; called once, on the control thread.
using Reply = std::function<void(std::string line)>;

// Called on the control thread with an admitted bind or replacement before it is committed; calls
// `commit` once, on the control thread, at once or later (the federation first claims the networks
// the plan adds load to, for gateway.federation.claim_window). Until then other changes are `busy`.
// The commit admits the channels again when anything changed meanwhile.
using BindGate = std::function<void(const BindPlan& plan, std::function<void()> commit)>;

// Bounds of a request the parser accepts (no recursion over attacker-chosen nesting).
inline constexpr int kMaxRequestNesting = 16;
// A replacement's wait for its new publishers to match (request field match_timeout_s).
inline constexpr double kDefaultMatchTimeoutS = 5.0;
inline constexpr double kMaxMatchTimeoutS = 60.0;
// Characters of a client-chosen text (command, channel name) quoted in a log line.
inline constexpr std::size_t kMaxLoggedText = 64;

namespace control_detail {
class EchoTaps;
}

class ControlProtocol {
 public:
  // `reload_source` re-reads the daemon's configuration file (on the worker thread when
  // `offload` is given). Without `offload`, admission runs inline on the calling thread.
  ControlProtocol(Gateway& gateway, std::function<ConfigResult()> reload_source, AccessPolicy policy, Logger& log,
                  ChangeObserver on_change = {}, Offload offload = {});
  ~ControlProtocol();  // closes the taps echo opened
  ControlProtocol(const ControlProtocol&) = delete;
  ControlProtocol& operator=(const ControlProtocol&) = delete;

  // The answer line now, or nullopt when a bind or reload runs off the control thread: `later`
  // then gets the answer. While one runs, every bind, unbind and reload is answered `busy`.
  std::optional<std::string> handle(std::string_view request_line, const PeerCredentials& peer, const Reply& later);
  // The same for callers without an Offload (every answer is immediate).
  std::string handle(std::string_view request_line, const PeerCredentials& peer);
  bool admission_running() const { return !running_.empty(); }
  // Adds a read-only command (may_read applies) answered by `answer` on the control thread, e.g.
  // `peers` from the daemon's federation; its answer carries "ok" itself.
  void add_reader(std::string command, std::function<nlohmann::json()> answer) {
    readers_[std::move(command)] = std::move(answer);
  }
  // Adds a command that changes the gateway (may_modify applies) answered by `answer` on the control
  // thread, e.g. `record_start` from the daemon's recorder; its answer carries "ok" itself.
  void add_operator(std::string command, std::function<nlohmann::json(const nlohmann::json& request)> answer) {
    operators_[std::move(command)] = std::move(answer);
  }
  // Installs the gate binds pass before their commit (only with an Offload: inline binds commit at once).
  void set_bind_gate(BindGate gate) { gate_ = std::move(gate); }
  // The output channels whose FMU's runner reports a worst step longer than its step, with the
  // reason (FmuReports::overruns), for Gateway::set_reported_violations.
  std::map<std::string, std::string> fmu_overruns(std::chrono::steady_clock::time_point now) const {
    return fmu_reports_.overruns(gateway_.config().fmus, now);
  }

  static bool is_mutating(std::string_view command);

 private:
  using Json = nlohmann::json;
  // Holds the answer, or nothing when it will come through `later`.
  using Answer = std::optional<Json>;
  Answer dispatch(const Json& request, const PeerCredentials& peer, const Reply& later);
  Answer mutate(const std::string& command, const Json& request, const PeerCredentials& peer, const Reply& later);
  Json finish(const std::string& command, const Json& request, Json answer);
  // Runs `work` through offload_ (or inline) and answers with `done`'s result.
  // `done` returns the answer, or nothing when it arranged to give it through `later` itself.
  Answer run_admission(std::string what, std::function<void()> work, std::function<Answer()> done, const Reply& later);
  // Commits a bind plan and answers. `replan`: admit it again first if the bindings changed since
  // it was made (after a claim window); otherwise such a commit is refused ("try again").
  Json commit_planned(BindPlan plan, const Json& request, const std::string& command, bool replan);
  // A planned bind's last step: commit_planned() (a bind), or switch_planned() (a replacement).
  Answer conclude(std::shared_ptr<BindPlan> plan, const Json& request, const std::string& command, bool replan,
                  const Reply& later);
  // A replacement made before break (control_switch_over.cpp): admitted again when `replan` and the
  // bindings changed, its new hops opened, then the switch once every new publisher has matched or
  // the request's match timeout passed. The wait polls through offload_ (the control thread stays
  // free; other changes are `busy` meanwhile); without offload_ it polls here.
  struct SwitchWait;
  Answer switch_planned(std::shared_ptr<BindPlan> plan, const Json& request, const std::string& command, bool replan,
                        const Reply& later);
  void await_match(const std::shared_ptr<SwitchWait>& wait);
  Json switched(SwitchWait& wait, bool timed_out);
  std::string next_log_tag(const char* kind, const PeerCredentials& peer);
  Json status() const;
  Json segments() const;
  Json channels() const;
  Json channel(const Json& request) const;
  Json unbound_channel(const std::string& name) const;
  // `replace`: the channels take the place of bound ones of the same names (Gateway::replace).
  Answer bind(const Json& request, bool replace, const Reply& later);
  Json unbind(const Json& request);
  Answer reload(const Reply& later);
  // Run-time replays (control_replay.cpp): `replay` adds a replay segment and swaps it in as the
  // publisher of the recorded channels (or beside their publishers); `replay_stop` swaps the
  // definitions back and removes the segment. A reload ends them all (its file does not name them).
  struct RunTimeReplay {
    std::string name;                   // the segment's
    std::string file;                   // the recording
    std::vector<ChannelSpec> before;    // the channels' definitions when the replay began
    std::vector<ChannelSpec> replayed;  // what the replay bound in their place
  };
  Answer replay(const Json& request, const Reply& later);
  Answer begin_replay(SegmentSpec segment, const Json& request, const Reply& later);
  Answer stop_replay(const Json& request, const Reply& later);
  // After a replacement's switch (control_switch_over.cpp): a replay's start or stop completed or
  // undone, the segment removed where it no longer serves.
  void settle_replay(const std::string& command, const BindResult& result, Json& answer);
  std::optional<Json> bad_match_timeout(const Json& request) const;
  // The run-time replay whose segment `channel` names, or empty.
  std::string run_time_replay_in(const ChannelSpec& channel) const;
  // Removes a replay's segment; one that cannot go stays listed (nothing to restore) for replay_stop.
  void drop_segment(RunTimeReplay replay);
  // A replay whose switch failed with an exception: its segment removed, nothing left pending.
  void abandon_replay();
  Json channel_entry(const ChannelReport& verdict, const ChannelStatsSnapshot* stats) const;

  Gateway& gateway_;
  std::function<ConfigResult()> reload_source_;
  AccessPolicy policy_;
  Logger& log_;
  ChangeObserver on_change_;
  Offload offload_;
  std::chrono::steady_clock::time_point started_;
  std::string running_;             // what admission runs off the control thread, for `busy` answers
  std::uint64_t log_sequence_ = 0;  // numbers audit and denial lines: no two are alike, none folded
  DenialLog denials_;               // which denials are logged (a burst is summarised)
  std::map<std::string, std::function<Json()>> readers_;               // add_reader()
  std::map<std::string, std::function<Json(const Json&)>> operators_;  // add_operator()
  BindGate gate_;
  std::map<std::string, RunTimeReplay> replays_;    // by segment name
  std::optional<RunTimeReplay> pending_replay_;     // a replay or replay_stop while its switch runs
  std::unique_ptr<control_detail::EchoTaps> echo_;  // echo_open, echo_read, echo_close
  FmuReports fmu_reports_;                          // fmu_report, fmus, and each channel's FMU part
};

}  // namespace cosmic

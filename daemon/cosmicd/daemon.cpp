#include "daemon.hpp"

#include <grp.h>
#include <sys/mman.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "adapter_factory.hpp"
#include "binding_store.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/control_server.hpp"
#include "cosmic/dds_federation_link.hpp"
#include "cosmic/thread_policy.hpp"
#include "daemon_logger.hpp"
#include "federation_member.hpp"
#include "recording_service.hpp"
#include "metrics_server.hpp"
#include "realtime_watchdog.hpp"
#include "service_notifier.hpp"

namespace cosmicd {
namespace {

std::uint64_t random_gateway_id() {
  std::random_device device;
  std::uint64_t id = 0;
  while (id == 0) id = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  return id;
}

// The absolute directory of the state file (a relative --state-file is the working directory's).
std::string directory_of(const std::string& file) {
  std::error_code failed;
  const std::filesystem::path absolute = std::filesystem::absolute(file, failed);
  return (failed ? std::filesystem::path(file) : absolute).parent_path().string();
}

std::string default_state_file() {
  const char* directory = std::getenv("STATE_DIRECTORY");  // set by systemd's StateDirectory=
  const std::string base =
      directory ? std::string(directory).substr(0, std::string(directory).find(':')) : "/var/lib/cosmicd";
  return base + "/bindings.json";
}

void log_verdicts(cosmic::Logger& log, const std::vector<cosmic::ChannelReport>& channels) {
  for (const auto& channel : channels) {
    std::string line =
        "channel " + channel.name + " (" + cosmic::to_string(channel.cls) + "): " + cosmic::to_string(channel.verdict);
    for (const auto& reason : channel.reasons) line += "; " + reason;
    log.log(channel.verdict == cosmic::Verdict::bound ? cosmic::LogLevel::info : cosmic::LogLevel::warning, line);
  }
}

// Blocks the termination and reload signals in every thread and returns a signalfd for them.
int signal_descriptor() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  return signalfd(-1, &signals, SFD_NONBLOCK | SFD_CLOEXEC);
}

cosmic::Nanos steady_now() {
  return std::chrono::duration_cast<cosmic::Nanos>(std::chrono::steady_clock::now().time_since_epoch());
}

class Daemon {
 public:
  explicit Daemon(const DaemonOptions& options)
      : options_(options),
        log_(parse_log_level(options.log_level)),
        state_file_(options.state_file.empty() ? default_state_file() : options.state_file),
        adapters_(directory_of(state_file_),
                  [this](const cosmic::SegmentSpec& segment) { return recording_.wire_tap(segment); }),
        gateway_([this](const cosmic::SegmentSpec& segment, const cosmic::GatewayIdentity& self,
                        cosmic::Logger& log) { return adapters_.make(segment, self, log); },
                 log_, random_gateway_id()),
        federation_(gateway_, log_, cosmic::make_dds_federation_link) {}

  int run() {
    const int signal_fd = signal_descriptor();
    const auto loaded = config_loader_.load(options_.config);
    if (!loaded.ok()) {
      for (const auto& error : loaded.errors) log_.log(cosmic::LogLevel::error, error.to_string());
      return kExitConfigError;
    }
    if (!start(loaded.config)) return kExitStartFailure;
    const cosmic::AccessPolicy policy = make_access_policy(options_.groups);
    cosmic::ControlServerOptions server_options;
    server_options.path = options_.socket.empty() ? loaded.config.gateway.control_socket : options_.socket;
    server_options.privileged = policy.may_modify;  // admins keep reserved control slots
    if (const ::group* g = ::getgrnam(options_.groups.read_group.c_str())) server_options.socket_group = g->gr_gid;
    cosmic::ControlServer server(server_options, [this](std::string_view line, const cosmic::PeerCredentials& peer,
                                                        const cosmic::ControlServer::Responder& later) {
      return protocol_->handle(line, peer, later);
    });
    // Admission of bind and reload runs on the server's worker thread, so status answers and
    // watchdog keep-alives continue meanwhile.
    cosmic::ControlProtocol protocol(
        gateway_, [this] { return config_loader_.load(options_.config); }, policy, log_,
        [this](const std::string& command, const nlohmann::json& request) { return remember(command, request); },
        server.offload());
    protocol_ = &protocol;
    protocol.add_reader("peers", [this] { return federation_.peers_json(steady_now()); });
    protocol.add_reader("record_status", [this] { return recording_.status(); });
    protocol.add_operator("record_start", [this](const nlohmann::json&) { return recording_.start(); });
    protocol.add_operator("record_stop", [this](const nlohmann::json&) { return recording_.stop(); });
    protocol.set_bind_gate([this](const cosmic::BindPlan& plan, std::function<void()> commit) {
      federation_.gate(plan, std::move(commit));
    });
    server.watch(signal_fd, [&] { on_signals(signal_fd); });
    if (const auto opened = server.open(); !opened.ok) {
      log_.log(cosmic::LogLevel::error, "control socket: " + opened.error);
      gateway_.stop();
      return kExitStartFailure;
    }
    log_.log(cosmic::LogLevel::notice,
             "cosmicd " + loaded.config.gateway.name + " running; control socket " + server_options.path);
    // /metrics asks for a snapshot only when scraped; it is taken here, on the control thread.
    metrics_.attach([this, &server] {
      server.post([this] {
        MetricsSnapshot snapshot = take_metrics_snapshot(gateway_, started_);
        snapshot.federation = federation_.snapshot(steady_now());
        snapshot.recording = recording_.recorder_status();
        metrics_.publish(std::move(snapshot));
      });
    });
    loop(server);
    metrics_.detach();  // before `server` goes: scrapes stop posting to it
    notifier_.stopping();
    server.close_all();  // joins the admission worker before `protocol` goes
    protocol_ = nullptr;
    federation_.leave();     // peers release this gateway's reservations now, not after the lease
    recording_.shut_down();  // the last file finished before the adapters go
    gateway_.stop();
    log_.log(cosmic::LogLevel::notice, "cosmicd stopped");
    return kExitOk;
  }

 private:
  bool start(cosmic::Config config) {
    file_config_ = config;  // before the channels unbound at run time are taken out
    const LoadedState persisted = load_binding_state(state_file_);
    if (!persisted.error.empty()) {
      // Never overwrite what may still hold runtime bindings: move it aside, or stop saving.
      const SetAside aside = set_aside_state_file(state_file_);
      if (aside.error.empty()) {
        log_.log(cosmic::LogLevel::error, persisted.error +
                                              (aside.moved_to.empty() ? "" : "; kept aside as " + aside.moved_to) +
                                              "; starting from the configuration alone");
      } else {
        state_file_usable_ = false;
        log_.log(cosmic::LogLevel::error, persisted.error + "; cannot keep it aside (" + aside.error +
                                              "): runtime changes will not be saved until it is repaired or removed");
      }
    }
    state_ = persisted.state;
    std::erase_if(config.channels, [&](const cosmic::ChannelSpec& c) {
      return std::find(state_.unbound.begin(), state_.unbound.end(), c.name) != state_.unbound.end();
    });
    // Before the gateway starts its threads: they start from this one and inherit the placement
    // of `other` unless their own kind has CPUs.
    for (const auto& problem : cosmic::place_process_threads(config.gateway.realtime.cpus.other))
      log_.log(cosmic::LogLevel::warning, "realtime: " + problem);
    std::vector<int> lanes_cpus = config.gateway.realtime.cpus.hrt;
    lanes_cpus.insert(lanes_cpus.end(), config.gateway.realtime.cpus.srt.begin(),
                      config.gateway.realtime.cpus.srt.end());
    watchdog_.keep_off(std::move(lanes_cpus));
    const auto started = gateway_.start(config);
    if (!started.applied) {
      log_.log(cosmic::LogLevel::error, started.error);
      return false;
    }
    log_verdicts(log_, started.channels);
    recording_.configure(gateway_, gateway_.config());
    report_realtime(config.gateway.realtime);
    restore_runtime_bindings();
    return true;
  }

  // gateway.realtime: memory locking is process-wide and done here; the thread priorities are
  // applied by each thread as it starts (their problems arrive through take_thread_problems()).
  void report_realtime(const cosmic::RealtimeSpec& realtime) {
    if (!realtime.requested()) {
      log_.log(cosmic::LogLevel::info,
               "realtime: not configured; forwarding threads run time-shared (NRT lanes at nice 10)");
      return;
    }
    if (realtime.lock_memory) {
      if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
        log_.log(cosmic::LogLevel::info, "realtime: memory locked (mlockall)");
      } else {
        log_.log(cosmic::LogLevel::warning,
                 std::string("realtime: mlockall failed: ") + std::strerror(errno) +
                     "; pages may be swapped out (raise LimitMEMLOCK or grant CAP_IPC_LOCK)");
      }
    }
    log_.log(cosmic::LogLevel::info, "realtime: SCHED_FIFO priorities hrt " + std::to_string(realtime.hrt_priority) +
                                         ", srt " + std::to_string(realtime.srt_priority) + ", nrt " +
                                         std::to_string(realtime.nrt_priority) + ", receive " +
                                         std::to_string(realtime.receive_priority));
    if (realtime.cpus.any()) {
      const cosmic::CpuPlacement& c = realtime.cpus;
      const auto list = [&c](const std::vector<int>& cpus) {
        if (cpus.empty()) return std::string(c.other.empty() ? "any" : "as other");
        std::string text;
        for (const int cpu : cpus) {
          if (!text.empty()) text.push_back(',');
          text.append(std::to_string(cpu));
        }
        return text;
      };
      log_.log(cosmic::LogLevel::info, "realtime: CPUs hrt " + list(c.hrt) + ", srt " + list(c.srt) + ", nrt " +
                                           list(c.nrt) + ", receive " + list(c.receive) + ", other " + list(c.other));
    }
  }

  // An entry that cannot be bound now (a segment down at boot, a changed configuration) stays
  // in the state file for the next start; only an entry that lies about its name is dropped.
  void restore_runtime_bindings() {
    std::vector<RuntimeBinding> kept;
    for (const auto& binding : state_.bound) {
      const auto parsed = cosmic::parse_channels(binding.yaml, state_file_, gateway_.config());
      if (const std::string wrong = check_binding_entry(binding, parsed.channels); parsed.ok() && !wrong.empty()) {
        log_.log(cosmic::LogLevel::error, state_file_ + ": " + wrong + "; entry dropped");
        continue;
      }
      kept.push_back(binding);
      const auto result = parsed.ok() ? gateway_.bind(parsed.channels) : cosmic::BindResult{};
      if (result.applied) {
        log_.log(cosmic::LogLevel::notice, "restored runtime binding of channel " + binding.name);
        continue;
      }
      std::string why =
          parsed.ok() ? result.error : std::to_string(parsed.errors.size()) + " error(s) in its definition";
      if (!parsed.ok()) why += ": " + parsed.errors.front().to_string();
      log_.log(cosmic::LogLevel::warning, "runtime binding of channel " + binding.name + " could not be restored (" +
                                              why + "); kept in the state file for the next start");
    }
    if (kept.size() != state_.bound.size()) {
      state_.bound = std::move(kept);
      persist();
    }
  }

  // Returns why the new state could not be saved, or an empty string.
  std::string remember(const std::string& command, const nlohmann::json& request) {
    // A run-time replay lasts until replay_stop, a reload or the next start: nothing to keep.
    if (command == "replay" || command == "replay_stop") return {};
    if (command == "reload") {
      state_ = {};  // the file is the truth again
      file_config_ = gateway_.config();
      recording_.configure(gateway_, gateway_.config());
    } else if (command == "bind" || command == "replace") {
      // A replacement is saved as a bind of the new definitions: at the next start they are
      // bound in place of the file's (or the earlier runtime) definitions of the same names.
      const auto parsed = cosmic::parse_channels(request["yaml"].get<std::string>(), command, gateway_.config());
      for (const auto& channel : parsed.channels) {
        std::erase_if(state_.bound, [&](const RuntimeBinding& b) { return b.name == channel.name; });
        std::erase(state_.unbound, channel.name);
        const cosmic::ChannelSpec* in_file = file_config_.find_channel(channel.name);
        if (in_file && *in_file == channel) continue;         // the file's own definition again
        if (in_file) state_.unbound.push_back(channel.name);  // replaces the file's definition
        state_.bound.push_back({channel.name, cosmic::channel_to_yaml(channel)});
      }
    } else if (command == "unbind") {
      const std::string name = request["name"].get<std::string>();
      std::erase_if(state_.bound, [&](const RuntimeBinding& b) { return b.name == name; });
      if (file_config_.find_channel(name) &&
          std::find(state_.unbound.begin(), state_.unbound.end(), name) == state_.unbound.end()) {
        state_.unbound.push_back(name);
      }
    }
    return persist();
  }

  std::string persist() {
    std::string error = state_file_usable_ ? save_binding_state(state_file_, state_)
                                           : state_file_ + " is unusable and could not be set aside; not overwritten";
    if (!error.empty()) log_.log(cosmic::LogLevel::error, "cannot save runtime bindings: " + error);
    return error;
  }

  void on_signals(int signal_fd) {
    signalfd_siginfo info{};
    while (read(signal_fd, &info, sizeof info) == sizeof info) {
      if (info.ssi_signo == SIGHUP) {
        reload();
      } else {
        log_.log(cosmic::LogLevel::notice, "signal " + std::to_string(info.ssi_signo) + ": shutting down");
        running_ = false;
      }
    }
  }

  // SIGHUP takes the control socket's path (root asking): the same validation, the same
  // off-thread admission, and `busy` while another admission runs.
  void reload() {
    notifier_.reloading();
    log_.log(cosmic::LogLevel::notice, "SIGHUP: reloading " + options_.config);
    const cosmic::PeerCredentials self{static_cast<int>(::getpid()), 0, 0};
    auto finished = [this](const std::string& line) {
      log_reload_answer(nlohmann::json::parse(line, nullptr, false));
      notifier_.reloaded(gateway_);
    };
    if (auto now = protocol_->handle(R"({"command":"reload"})", self, finished)) finished(*now);
  }

  void log_reload_answer(const nlohmann::json& answer) {
    if (answer.is_discarded()) return;
    for (const auto& c : answer.value("channels", nlohmann::json::array())) {
      std::string line =
          "channel " + c.value("name", "") + " (" + c.value("class", "") + "): " + c.value("verdict", "");
      for (const auto& reason : c.value("reasons", nlohmann::json::array())) line += "; " + reason.get<std::string>();
      log_.log(c.value("verdict", "") == "bound" ? cosmic::LogLevel::info : cosmic::LogLevel::warning, line);
    }
    if (answer.value("ok", false)) return;
    for (const auto& error : answer.value("errors", nlohmann::json::array()))
      log_.log(cosmic::LogLevel::error, error.value("text", ""));
    const auto& error = answer["error"];
    log_.log(cosmic::LogLevel::error, "reload refused (" + error.value("code", "failed") + "): " +
                                          error.value("message", "") + "; the running configuration is unchanged");
  }

  void loop(cosmic::ControlServer& server) {
    auto last_health = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    auto last_watchdog = std::chrono::steady_clock::now();
    while (running_) {
      server.run_for(std::chrono::milliseconds(100));
      federation_.tick(steady_now());
      if (std::chrono::steady_clock::now() - last_watchdog >= std::chrono::seconds(1)) {
        for (const auto& line : watchdog_.check(steady_now())) log_.log(cosmic::LogLevel::error, "realtime: " + line);
        last_watchdog = std::chrono::steady_clock::now();
      }
      if (std::chrono::steady_clock::now() - last_health >= std::chrono::milliseconds(250)) {
        gateway_.refresh_health();
        // An FMU whose runner reports a step overrun flags its output channels as a miss would.
        gateway_.set_reported_violations(protocol_->fmu_overruns(std::chrono::steady_clock::now()));
        gateway_.refresh_runtime(steady_now());
        for (const auto& problem : gateway_.take_thread_problems())
          log_.log(cosmic::LogLevel::warning, "realtime: " + problem);
        notifier_.tick(gateway_);
        metrics_.follow(gateway_.config().gateway.metrics);  // a reload may move or close the endpoint
        last_health = std::chrono::steady_clock::now();
      }
    }
  }

  DaemonOptions options_;
  DaemonLogger log_;
  std::string state_file_;
  AdapterFactory adapters_;           // before gateway_: the adapters' shared state outlives them
  bool state_file_usable_ = true;     // false: unusable at start and could not be set aside
  RecordingService recording_{log_};  // before gateway_: the router may call its recorder until it stops
  cosmic::Gateway gateway_;
  FederationMember federation_;  // after gateway_: it uses the gateway until it is destroyed
  ServiceNotifier notifier_;
  RealtimeWatchdog watchdog_;  // a busy real-time thread is made time-shared
  BindingState state_;
  cosmic::Config file_config_;  // the configuration file as last loaded
  // Start and then the admission worker, one reload at a time: an unchanged file is not parsed again.
  cosmic::ConfigFileLoader config_loader_;
  bool running_ = true;
  cosmic::ControlProtocol* protocol_ = nullptr;  // while run() serves the control socket
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  MetricsServer metrics_{log_};  // last: its threads stop before anything they were given goes
};

}  // namespace

int run_daemon(const DaemonOptions& options) { return Daemon(options).run(); }

}  // namespace cosmicd

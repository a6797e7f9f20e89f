// The control protocol of cosmicd (docs/control-protocol.md): one JSON object per line in each
// direction over a Unix stream socket. This part turns a request line into a response line; it
// does no I/O of its own. Called by the control thread only.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <functional>
#include <string>
#include <string_view>

#include "cosmic/config_loader.hpp"
#include "cosmic/gateway.hpp"

namespace cosmic {

// Who is asking (from SO_PEERCRED).
struct PeerCredentials {
  int pid = -1;
  unsigned uid = 0;
  unsigned gid = 0;
};

// Decides whether a peer may run a command class; installed by the daemon.
struct AccessPolicy {
  std::function<bool(const PeerCredentials&)> may_read = [](const PeerCredentials&) { return true; };
  std::function<bool(const PeerCredentials&)> may_modify = [](const PeerCredentials&) { return true; };
};

// Told about every mutating command that changed the gateway (e.g. to persist it).
using ChangeObserver = std::function<void(const std::string& command, const nlohmann::json& request)>;

class ControlProtocol {
 public:
  // `reload_source` re-reads the daemon's configuration file.
  ControlProtocol(Gateway& gateway, std::function<ConfigResult()> reload_source, AccessPolicy policy, Logger& log,
                  ChangeObserver on_change = {});

  std::string handle(std::string_view request_line, const PeerCredentials& peer);

  static bool is_mutating(std::string_view command);

 private:
  using Json = nlohmann::json;
  Json dispatch(const Json& request, const PeerCredentials& peer);
  Json status() const;
  Json segments() const;
  Json channels() const;
  Json channel(const Json& request) const;
  Json bind(const Json& request);
  Json unbind(const Json& request);
  Json reload();
  Json channel_entry(const ChannelReport& verdict, const ChannelStatsSnapshot* stats) const;

  Gateway& gateway_;
  std::function<ConfigResult()> reload_source_;
  AccessPolicy policy_;
  Logger& log_;
  ChangeObserver on_change_;
  std::chrono::steady_clock::time_point started_;
};

}  // namespace cosmic

#include "metrics_snapshot.hpp"

#include <cstdio>

namespace cosmicd {

MetricsSnapshot take_metrics_snapshot(const cosmic::Gateway& gateway, std::chrono::steady_clock::time_point started) {
  MetricsSnapshot out;
  out.gateway_name = gateway.identity().name;
  char id[20];
  std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(gateway.identity().id));
  out.gateway_id = id;
  out.uptime_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  out.residence_bound = gateway.config().gateway.residence_bound;
  out.router_queued = gateway.router().queued();
  out.router_handled = gateway.router().progress();
  out.segments = gateway.segments();
  out.channels = gateway.admission().channels;
  out.stats = gateway.channel_stats();
  return out;
}

}  // namespace cosmicd

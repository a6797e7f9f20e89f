// The opt-in HTTP endpoint of gateway.metrics (docs/metrics.md), on cpp-httplib with our own
// connection handling (metrics_http_server.hpp: deadlines, head limit, connection cap).
//
// Threads: follow(), attach(), detach() and publish() are called by the control thread only. HTTP
// is served by the endpoint's own threads, all named "cosmic-metrics"; they never touch the
// Gateway. A scrape asks the control thread for a snapshot (SnapshotRelay: only while scrapes
// happen, at most one per 100 ms) and renders that shared, immutable MetricsSnapshot, so a scrape
// costs the forwarding threads nothing and a slow scraper cannot stall the control loop.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/result.hpp"
#include "metrics_relay.hpp"
#include "metrics_snapshot.hpp"

namespace cosmicd {

class MetricsServer {
 public:
  explicit MetricsServer(cosmic::Logger& log);
  ~MetricsServer();
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  // Serves what `spec` asks for: opens, moves or closes the endpoint when `spec` differs from
  // the last one asked for (so a failed bind is reported once, not every call). A new address
  // that cannot be bound keeps the endpoint on the old one.
  void follow(const cosmic::MetricsSpec& spec);
  // True while an endpoint listens.
  bool serving() const { return endpoint_ != nullptr; }
  // The address actually served ("http://127.0.0.1:9877/metrics"); empty when not serving.
  const std::string& url() const { return url_; }
  // How a scrape gets a snapshot: `ask` (called on a scrape's thread) must lead to publish() on
  // the control thread soon, e.g. by posting a task to its loop. Without it scrapes get the last
  // snapshot published, or 503.
  void attach(std::function<void()> ask) { relay_.attach(std::move(ask)); }
  // Call before what `ask` refers to goes away: scrapes stop asking and waiting.
  void detach() { relay_.detach(); }
  // The answer to `ask`: what the scrapes waiting (and those of the next 100 ms) render.
  void publish(MetricsSnapshot snapshot) { relay_.publish(std::move(snapshot)); }

 private:
  class Endpoint;
  cosmic::Result<std::unique_ptr<Endpoint>> open(const cosmic::MetricsSpec& spec);

  cosmic::Logger& log_;
  cosmic::MetricsSpec requested_;
  cosmic::MetricsSpec serving_spec_;
  std::string url_;
  SnapshotRelay<MetricsSnapshot> relay_;  // before endpoint_: its threads use it until they stop
  std::unique_ptr<Endpoint> endpoint_;
};

}  // namespace cosmicd

// The opt-in HTTP endpoint of gateway.metrics (docs/metrics.md), on cpp-httplib.
//
// Threads: follow() and publish() are called by the control thread only. HTTP is served by the
// endpoint's own threads, all named "cosmic-metrics"; they never touch the Gateway, only the
// last published MetricsSnapshot (shared, immutable), so a scrape costs the forwarding threads
// nothing and a slow scraper cannot stall the control loop.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
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
  // Makes `snapshot` what the next scrapes render.
  void publish(MetricsSnapshot snapshot);

 private:
  class Endpoint;
  std::unique_ptr<Endpoint> open(const cosmic::MetricsSpec& spec, std::string& error);
  std::shared_ptr<const MetricsSnapshot> latest() const;

  cosmic::Logger& log_;
  cosmic::MetricsSpec requested_;
  cosmic::MetricsSpec serving_spec_;
  std::string url_;
  std::unique_ptr<Endpoint> endpoint_;
  mutable std::mutex mutex_;  // guards latest_, shared with the HTTP threads
  std::shared_ptr<const MetricsSnapshot> latest_;
};

}  // namespace cosmicd

#include "metrics_server.hpp"

#include <pthread.h>

#include <cerrno>
#include <cstring>
#include <thread>

#include "metrics_http_server.hpp"
#include "metrics_render.hpp"

namespace cosmicd {
namespace {

void name_this_thread() { pthread_setname_np(pthread_self(), "cosmic-metrics"); }

std::string url_of(const cosmic::MetricsSpec& spec) {
  const bool v6 = spec.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + spec.host + "]" : spec.host) + ":" + std::to_string(spec.port) + "/metrics";
}

}  // namespace

class MetricsServer::Endpoint {
 public:
  explicit Endpoint(cosmic::Logger& log) : http(HttpLimits{}, name_this_thread, &log) {}
  MetricsHttpServer http;
  std::thread thread;

  ~Endpoint() {
    http.close_connections();
    http.stop();
    if (thread.joinable()) thread.join();
  }
};

MetricsServer::MetricsServer(cosmic::Logger& log) : log_(log) {}

MetricsServer::~MetricsServer() { endpoint_.reset(); }

cosmic::Result<std::unique_ptr<MetricsServer::Endpoint>> MetricsServer::open(const cosmic::MetricsSpec& spec) {
  auto endpoint = std::make_unique<Endpoint>(log_);
  MetricsHttpServer& http = endpoint->http;
  http.serve_metrics([this](ExpositionFormat format) -> std::optional<std::string> {
    const auto snapshot = relay_.get();
    if (!snapshot) return std::nullopt;
    return render_metrics(*snapshot, format);
  });
  errno = 0;
  if (!http.bind(spec.host, spec.port)) {
    const int err = errno;
    if (err != 0) return cosmic::Error::from_errno("cannot listen on " + url_of(spec), err);
    return cosmic::Error{"cannot listen on " + url_of(spec)};
  }
  endpoint->thread = std::thread([&http] {
    name_this_thread();
    http.listen_after_bind();
  });
  return endpoint;
}

void MetricsServer::follow(const cosmic::MetricsSpec& spec) {
  if (spec == requested_) return;
  requested_ = spec;
  const std::string old_url = url_;
  const cosmic::MetricsSpec old_spec = serving_spec_;
  endpoint_.reset();  // frees the port: a new address may be the same port on another host
  url_.clear();
  if (!spec.enabled) {
    if (!old_url.empty()) log_.log(cosmic::LogLevel::notice, "metrics endpoint " + old_url + " closed");
    return;
  }
  if (auto opened = open(spec)) {
    endpoint_ = std::move(opened).value();
    serving_spec_ = spec;
    url_ = url_of(spec);
    log_.log(cosmic::LogLevel::notice, "metrics endpoint listening on " + url_);
    return;
  } else {
    log_.log(cosmic::LogLevel::error, "metrics endpoint: " + opened.error().text);
  }
  if (old_url.empty()) return;
  if (auto again = open(old_spec)) {
    endpoint_ = std::move(again).value();
    url_ = old_url;
    log_.log(cosmic::LogLevel::warning, "metrics endpoint stays on " + old_url);
  } else {
    log_.log(cosmic::LogLevel::error, "metrics endpoint: " + again.error().text + "; no metrics are served");
  }
}

}  // namespace cosmicd

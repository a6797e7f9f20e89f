#include "metrics_server.hpp"

#include <httplib.h>
#include <pthread.h>

#include <cerrno>
#include <cstring>
#include <thread>

#include "metrics_render.hpp"

namespace cosmicd {
namespace {

constexpr const char* kThreadName = "cosmic-metrics";
// Two scrapers at once (Prometheus and an operator's curl); an idle keep-alive connection
// gives its worker back after a second.
constexpr std::size_t kWorkers = 2;
constexpr time_t kKeepAliveSeconds = 1;
constexpr time_t kIoTimeoutSeconds = 5;

void name_this_thread() { pthread_setname_np(pthread_self(), kThreadName); }

// httplib's pool, with every worker named after us (its threads start anonymous).
class NamedPool : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> task) override {
    pool_.enqueue([task = std::move(task)] {
      name_this_thread();
      task();
    });
  }
  void shutdown() override { pool_.shutdown(); }

 private:
  httplib::ThreadPool pool_{kWorkers};
};

std::string url_of(const cosmic::MetricsSpec& spec) {
  const bool v6 = spec.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + spec.host + "]" : spec.host) + ":" + std::to_string(spec.port) + "/metrics";
}

}  // namespace

class MetricsServer::Endpoint {
 public:
  httplib::Server http;
  std::thread thread;

  ~Endpoint() {
    http.stop();
    if (thread.joinable()) thread.join();
  }
};

MetricsServer::MetricsServer(cosmic::Logger& log) : log_(log) {}

MetricsServer::~MetricsServer() { endpoint_.reset(); }

std::unique_ptr<MetricsServer::Endpoint> MetricsServer::open(const cosmic::MetricsSpec& spec, std::string& error) {
  auto endpoint = std::make_unique<Endpoint>();
  httplib::Server& http = endpoint->http;
  http.new_task_queue = [] { return new NamedPool(); };
  http.set_keep_alive_timeout(kKeepAliveSeconds);
  http.set_read_timeout(kIoTimeoutSeconds);
  http.set_write_timeout(kIoTimeoutSeconds);
  http.set_payload_max_length(4096);
  http.Get("/metrics", [this](const httplib::Request& request, httplib::Response& response) {
    const auto snapshot = relay_.get();
    if (!snapshot) {
      response.status = 503;
      response.set_content("cosmicd did not answer with a snapshot in time\n", "text/plain");
      return;
    }
    const ExpositionFormat format = format_for_accept(request.get_header_value("Accept"));
    response.set_content(render_metrics(*snapshot, format), content_type(format));
  });
  http.Get("/", [](const httplib::Request&, httplib::Response& response) {
    response.set_content("cosmicd: metrics at /metrics\n", "text/plain");
  });
  errno = 0;
  if (!http.bind_to_port(spec.host, spec.port)) {
    error = "cannot listen on " + url_of(spec) + (errno ? std::string(": ") + std::strerror(errno) : std::string());
    return nullptr;
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
  std::string error;
  endpoint_ = open(spec, error);
  if (endpoint_) {
    serving_spec_ = spec;
    url_ = url_of(spec);
    log_.log(cosmic::LogLevel::notice, "metrics endpoint listening on " + url_);
    return;
  }
  log_.log(cosmic::LogLevel::error, "metrics endpoint: " + error);
  if (old_url.empty()) return;
  std::string again;
  endpoint_ = open(old_spec, again);
  if (endpoint_) {
    url_ = old_url;
    log_.log(cosmic::LogLevel::warning, "metrics endpoint stays on " + old_url);
  } else {
    log_.log(cosmic::LogLevel::error, "metrics endpoint: " + again + "; no metrics are served");
  }
}

}  // namespace cosmicd

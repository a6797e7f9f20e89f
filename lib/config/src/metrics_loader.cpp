// gateway.metrics (metrics_loader.hpp).
#include "metrics_loader.hpp"

#include "listen_address.hpp"

namespace cosmic::config_detail {

std::optional<MetricsSpec> parse_metrics(YamlReader& reader, const YAML::Node& node, const std::string& path) {
  if (!reader.check_map(node, path, {"listen", "allow_remote"})) return std::nullopt;
  MetricsSpec metrics;
  if (has(node, "allow_remote")) {
    if (auto v = reader.boolean(node["allow_remote"], key(path, "allow_remote"))) metrics.allow_remote = *v;
  }
  if (!has(node, "listen")) {
    // Present without a value: check_map has reported it.
    if (!node["listen"]) {
      reader.error_at(node, key(path, "listen"), "missing required key 'listen'", "HOST:PORT, e.g. 127.0.0.1:9877");
    }
    return std::nullopt;
  }
  const auto text = reader.string(node["listen"], key(path, "listen"));
  if (!text) return std::nullopt;
  const ListenAddress listen = parse_listen_address(*text);
  if (!listen.error.empty()) {
    reader.error_at(node["listen"], key(path, "listen"), "'" + *text + "' " + listen.error,
                    "IP:PORT such as 127.0.0.1:9877 or [::1]:9877");
    return std::nullopt;
  }
  if (!listen.loopback && !metrics.allow_remote) {
    reader.error_at(node["listen"], key(path, "listen"), "'" + *text + "' is not a loopback address",
                    "127.0.0.1:PORT or [::1]:PORT, or allow_remote: true to serve other hosts");
    return std::nullopt;
  }
  metrics.enabled = true;
  metrics.host = listen.host;
  metrics.port = listen.port;
  return metrics;
}

}  // namespace cosmic::config_detail

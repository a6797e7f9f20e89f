#include "top_view.hpp"

#include <cstdio>

#include "cosmic/report.hpp"
#include "cosmic/units.hpp"

namespace cosmicctl {
namespace {

using Json = nlohmann::json;
using cosmic::pad_column;

// The member `key`, or an empty JSON value: loops over it never see a temporary.
const Json& member(const Json& object, const char* key) {
  static const Json empty;
  return object.is_object() && object.contains(key) ? object[key] : empty;
}

std::string json_text(const Json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

std::uint64_t count_at(const Json& object, const char* key) {
  return object.is_object() && object.contains(key) && object[key].is_number_unsigned()
             ? object[key].get<std::uint64_t>()
             : 0;
}

std::string with_unit(double value, const char* format) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string rate_text(std::optional<double> rate) {
  if (!rate) return "-";
  if (*rate >= 1e6) return with_unit(*rate / 1e6, "%.1fM");
  if (*rate >= 1e4) return with_unit(*rate / 1e3, "%.1fk");
  return with_unit(*rate, "%.1f");
}

std::string column_micros(double seconds) { return with_unit(seconds * 1e6, "%.0fus"); }

// A counter's value in the previous sample, when there was one.
struct Prior {
  bool known = false;
  std::uint64_t value = 0;
};

// Rates between two samples of the same counters; a counter that went down restarted (the
// channel was bound again, cosmicd restarted) and has no rate this time.
class Rates {
 public:
  Rates(const TopSample& current, const std::optional<TopSample>& previous) : previous_(previous) {
    if (previous) seconds_ = std::chrono::duration<double>(current.taken - previous->taken).count();
  }

  std::optional<double> of(std::uint64_t now, Prior before) const {
    if (!before.known || seconds_ <= 0 || now < before.value) return std::nullopt;
    return static_cast<double>(now - before.value) / seconds_;
  }

  const Json* previous_segment(const std::string& name) const {
    if (!previous_) return nullptr;
    for (const auto& s : member(previous_->segments, "segments")) {
      if (s.value("name", "") == name) return &s;
    }
    return nullptr;
  }

  const Json* previous_hop(const std::string& channel, const std::string& segment) const {
    if (!previous_) return nullptr;
    for (const auto& c : member(previous_->channels, "channels")) {
      if (c.value("name", "") != channel) continue;
      for (const auto& s : member(c, "segments")) {
        if (s.value("segment", "") == segment) return &s;
      }
    }
    return nullptr;
  }

  Prior previous_progress() const {
    if (!previous_) return {};
    return {true, count_at(member(previous_->status, "router"), "progress")};
  }

 private:
  const std::optional<TopSample>& previous_;
  double seconds_ = 0;
};

Prior before(const Json* object, const char* key) { return object ? Prior{true, count_at(*object, key)} : Prior{}; }

std::uint64_t drops_of(const Json& hop) {
  std::uint64_t total = 0;
  for (const auto& [reason, count] : member(hop, "dropped").items()) total += count.get<std::uint64_t>();
  return total;
}

std::string drops_by_reason(const Json& hop) {
  std::string out;
  for (const auto& [reason, count] : member(hop, "dropped").items()) {
    if (count.get<std::uint64_t>() > 0) out += (out.empty() ? "" : " ") + reason + "=" + count.dump();
  }
  return out.empty() ? "-" : out;
}

TopLine header(const TopSample& current, const Rates& rates) {
  const Json& s = current.status;
  const Json& g = s["gateway"];
  const Json& router = s["router"];
  const std::uint64_t progress = count_at(router, "progress");
  const std::uint64_t violated = count_at(s["channels"], "violated");
  const std::uint64_t failed = count_at(s["channels"], "failed");
  std::string line = "cosmicd " + json_text(g["name"]) + " (id " + json_text(g["id"]) + "), up " +
                     std::to_string(static_cast<long>(g.value("uptime_s", 0.0))) + " s   segments " +
                     json_text(s["segments"]["up"]) + "/" + json_text(s["segments"]["total"]) + " up   channels " +
                     json_text(s["channels"]["bound"]) + " bound, " + json_text(s["channels"]["degraded"]) +
                     " degraded, " + std::to_string(failed) + " failed, " + std::to_string(violated) +
                     " violated   router " + json_text(router["queued"]) + " queued, " +
                     rate_text(rates.of(progress, rates.previous_progress())) + " ev/s";
  return {line, violated > 0 || failed > 0 || count_at(s["segments"], "up") < count_at(s["segments"], "total")};
}

void segment_rows(std::vector<TopLine>& out, const TopSample& current, const Rates& rates) {
  out.push_back({pad_column("SEGMENT", 14) + pad_column("TYPE", 5) + pad_column("HEALTH", 9) + pad_column("UTIL", 7) +
                 pad_column("RX/s", 9) + pad_column("TX/s", 9) + pad_column("ERR/s", 7) + pad_column("OVERFLOW", 9) +
                 "DETAIL"});
  for (const auto& s : member(current.segments, "segments")) {
    const Json& a = s["adapter"];
    const Json* old = rates.previous_segment(s.value("name", ""));
    const Json* old_adapter = old ? &(*old)["adapter"] : nullptr;
    const auto errors = count_at(a, "receive_errors") + count_at(a, "send_errors");
    const Prior old_errors =
        old_adapter ? Prior{true, count_at(*old_adapter, "receive_errors") + count_at(*old_adapter, "send_errors")}
                    : Prior{};
    const std::string health = json_text(s["health"]);
    out.push_back({pad_column(json_text(s["name"]), 14) + pad_column(json_text(s["type"]), 5) + pad_column(health, 9) +
                       pad_column(cosmic::format_percent(s.value("utilization", 0.0)), 7) +
                       pad_column(rate_text(rates.of(count_at(a, "received"), before(old_adapter, "received"))), 9) +
                       pad_column(rate_text(rates.of(count_at(a, "sent"), before(old_adapter, "sent"))), 9) +
                       pad_column(rate_text(rates.of(errors, old_errors)), 7) +
                       pad_column(json_text(a["overflow_drops"]), 9) + s.value("detail", ""),
                   health != "up"});
  }
}

std::string residence_of(const Json& hop) {
  if (!hop.contains("runtime")) return "-";
  return column_micros(hop["runtime"].value("residence_p50_s", 0.0)) + "/" +
         column_micros(hop["runtime"].value("residence_p99_s", 0.0));
}

std::string misses_of(const Json& hop) {
  if (!hop.contains("runtime")) return "-";
  return std::to_string(count_at(hop["runtime"], "residence_miss")) + "/" +
         std::to_string(count_at(hop["runtime"], "deadline_miss"));
}

void channel_rows(std::vector<TopLine>& out, const TopSample& current, const Rates& rates) {
  out.push_back({pad_column("CHANNEL", 16) + pad_column("CLASS", 6) + pad_column("SEGMENT", 12) +
                 pad_column("ROLE", 5) + pad_column("RX/s", 9) + pad_column("TX/s", 9) + pad_column("DROP/s", 8) +
                 pad_column("RES p50/p99", 16) + pad_column("MISS res/dl", 12) + pad_column("STATE", 9) + "DROPS"});
  for (const auto& c : member(current.channels, "channels")) {
    const std::string name = c.value("name", "");
    // A channel its transport refused shows that (verdict `failed`) rather than its runtime state.
    const std::string state = c.value("verdict", "") == "failed" ? "failed" : c.value("runtime_state", "bound");
    bool first = true;
    for (const auto& hop : member(c, "segments")) {
      const Json* old = rates.previous_hop(name, hop.value("segment", ""));
      const bool publisher = hop.value("role", "") == "publisher";
      const Prior old_drops = old ? Prior{true, drops_of(*old)} : Prior{};
      out.push_back({pad_column(first ? name : "", 16) + pad_column(first ? json_text(c["class"]) : "", 6) +
                         pad_column(json_text(hop["segment"]), 12) + pad_column(publisher ? "P" : "S", 5) +
                         pad_column(publisher ? rate_text(rates.of(count_at(hop, "rx"), before(old, "rx"))) : "-", 9) +
                         pad_column(publisher ? "-" : rate_text(rates.of(count_at(hop, "tx"), before(old, "tx"))), 9) +
                         pad_column(rate_text(rates.of(drops_of(hop), old_drops)), 8) +
                         pad_column(residence_of(hop), 16) + pad_column(misses_of(hop), 12) +
                         pad_column(first ? state : "", 9) + drops_by_reason(hop),
                     first && state != "bound"});
      first = false;
    }
  }
}

}  // namespace

std::vector<TopLine> top_frame(const TopSample& current, const std::optional<TopSample>& previous) {
  const Rates rates(current, previous);
  std::vector<TopLine> lines{header(current, rates), {}};
  segment_rows(lines, current, rates);
  lines.push_back({});
  channel_rows(lines, current, rates);
  return lines;
}

}  // namespace cosmicctl

#include "cosmic/fmu_reports.hpp"

#include <algorithm>
#include <limits>
#include <set>

#include "cosmic/units.hpp"

#include "bind_answer.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::json;

constexpr const char* kStates[] = {"starting", "running", "stopped", "failed"};
constexpr std::size_t kQuoted = 64;  // characters of a client-chosen name quoted in an answer

std::string quote_name(const std::string& text) {
  return "'" + text.substr(0, kQuoted) + (text.size() > kQuoted ? "...'" : "'");
}

std::string nothing_kept(const std::string& why) { return "fmu_report: " + why + "; nothing kept"; }

// request[key] as a whole number >= 0 into `out`, or why it is not one.
std::optional<std::string> read_count(const Json& request, const std::string& key, std::uint64_t& out) {
  if (!request.contains(key)) return "\"" + key + "\" is missing";
  const Json& value = request[key];
  if (value.is_number_unsigned() || (value.is_number_integer() && value.get<std::int64_t>() >= 0)) {
    out = value.get<std::uint64_t>();
    return std::nullopt;
  }
  const std::string text = value.dump();
  return "\"" + key + "\" must be a whole number >= 0, not " + text.substr(0, kQuoted) +
         (text.size() > kQuoted ? "..." : "");
}

// request[key] as a count of nanoseconds a duration holds (at most about 292 years), or why not.
std::optional<std::string> read_duration(const Json& request, const std::string& key, std::uint64_t& out) {
  if (auto why = read_count(request, key, out)) return why;
  constexpr auto kLongest = static_cast<std::uint64_t>(std::numeric_limits<Nanos::rep>::max());
  if (out > kLongest)
    return "\"" + key + "\" must be at most " + std::to_string(kLongest) + " ns, not " + std::to_string(out);
  return std::nullopt;
}

// The names a report's `skipped` may count under: the FMU's input variables and input channels.
std::set<std::string> input_names(const FmuSpec& fmu) {
  std::set<std::string> names;
  for (const auto& m : fmu.inputs) names.insert(m.variable);
  for (const auto& channel : fmu.subscribes()) names.insert(channel);
  return names;
}

std::optional<std::string> read_skipped(const Json& request, const FmuSpec& fmu, FmuReport& report) {
  if (!request.contains("skipped")) return "\"skipped\" is missing";
  const Json& skipped = request["skipped"];
  if (!skipped.is_object())
    return "\"skipped\" must be an object of input: count, not " + std::string(skipped.type_name());
  const std::set<std::string> inputs = input_names(fmu);
  for (const auto& [input, count] : skipped.items()) {
    if (!inputs.count(input)) {
      std::string known;
      for (const auto& name : inputs) known += (known.empty() ? "" : ", ") + name;
      return "\"skipped\" counts " + quote_name(input) + ", none of the FMU's inputs (" +
             (known.empty() ? "it has none" : known) + ")";
    }
    std::uint64_t value = 0;
    if (auto why = read_count(skipped, input, value)) return "\"skipped\": " + *why;
    report.skipped[input] = value;
  }
  return std::nullopt;
}

std::optional<std::string> read_report(const Json& request, const FmuSpec& fmu, FmuReport& report) {
  if (!request.contains("state") || !request["state"].is_string()) return "\"state\" (string) is required";
  report.state = request["state"].get<std::string>();
  if (std::find(std::begin(kStates), std::end(kStates), report.state) == std::end(kStates))
    return "unknown state " + quote_name(report.state) + " (starting, running, stopped or failed)";
  const std::pair<const char*, std::uint64_t*> counts[] = {{"steps", &report.steps},
                                                           {"late_steps", &report.late_steps}};
  for (const auto& [key, out] : counts) {
    if (auto why = read_count(request, key, *out)) return why;
  }
  const std::pair<const char*, std::uint64_t*> durations[] = {
      {"step_ns", &report.step_ns}, {"worst_step_ns", &report.worst_step_ns}, {"p99_step_ns", &report.p99_step_ns}};
  for (const auto& [key, out] : durations) {
    if (auto why = read_duration(request, key, *out)) return why;
  }
  if (report.step_ns == 0) return "\"step_ns\" must be > 0";
  if (auto why = read_skipped(request, fmu, report)) return why;
  if (request.contains("message")) {
    if (!request["message"].is_string()) return "\"message\" must be a string";
    report.message = request["message"].get<std::string>();
  }
  return std::nullopt;
}

const FmuSpec* find_fmu(const std::vector<FmuSpec>& fmus, const std::string& name) {
  const auto it = std::find_if(fmus.begin(), fmus.end(), [&](const FmuSpec& f) { return f.name == name; });
  return it == fmus.end() ? nullptr : &*it;
}

bool report_stale(const FmuReport& report, FmuReports::Clock::time_point now) {
  return now - report.received > FmuReports::kStaleAfter;
}

Json report_json(const FmuReport& r, FmuReports::Clock::time_point now) {
  return Json{{"state", r.state},
              {"step_ns", r.step_ns},
              {"steps", r.steps},
              {"late_steps", r.late_steps},
              {"worst_step_ns", r.worst_step_ns},
              {"p99_step_ns", r.p99_step_ns},
              {"skipped", r.skipped},
              {"message", r.message},
              {"age_s", std::chrono::duration<double>(now - r.received).count()},
              {"stale", report_stale(r, now)}};
}

// A reported count of nanoseconds as a duration (a count beyond what one holds is the longest).
Nanos nanos(std::uint64_t count) {
  return Nanos(static_cast<Nanos::rep>(std::min<std::uint64_t>(count, std::numeric_limits<Nanos::rep>::max())));
}

bool names_contain(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

Json FmuReports::accept(const Json& request, const std::vector<FmuSpec>& fmus, Clock::time_point now) {
  if (!request.contains("name") || !request["name"].is_string())
    return failure("bad_request", nothing_kept("\"name\" (string) is required: the FMU's name in fmus:"));
  const std::string name = request["name"].get<std::string>();
  const FmuSpec* fmu = find_fmu(fmus, name);
  if (fmu == nullptr) {
    std::string known;
    for (const auto& f : fmus) known += (known.empty() ? "" : ", ") + f.name;
    return failure("not_found", nothing_kept("no FMU named " + quote_name(name) + " in the running configuration (" +
                                             (known.empty() ? "it has no fmus:" : "its FMUs: " + known) + ")"));
  }
  FmuReport report;
  if (auto why = read_report(request, *fmu, report)) return failure("bad_request", nothing_kept(*why));
  report.received = now;
  reports_[name] = std::move(report);
  return Json{{"ok", true}};
}

void FmuReports::keep_configured(const std::vector<FmuSpec>& fmus) {
  std::erase_if(reports_, [&](const auto& entry) { return find_fmu(fmus, entry.first) == nullptr; });
}

const FmuReport* FmuReports::find(const std::string& fmu) const {
  const auto it = reports_.find(fmu);
  return it == reports_.end() ? nullptr : &it->second;
}

std::optional<std::string> FmuReports::overrun(const FmuSpec& fmu, Clock::time_point now) const {
  const FmuReport* r = find(fmu.name);
  // Judged against the configured step, not the one the report names (a runner still on an older
  // configuration, or any sender, does not choose the step it is held to).
  const auto step = static_cast<std::uint64_t>(fmu.step.count());
  if (r == nullptr || report_stale(*r, now) || r->worst_step_ns <= step) return std::nullopt;
  return "fmu " + fmu.name + "'s worst step " + format_duration(nanos(r->worst_step_ns)) + " exceeds its step " +
         format_duration(fmu.step);
}

Json FmuReports::fmus_answer(const std::vector<FmuSpec>& fmus, Clock::time_point now) const {
  Json list = Json::array();
  for (const FmuSpec& f : fmus) {
    const FmuReport* r = find(f.name);
    const auto why = overrun(f, now);
    list.push_back(Json{{"name", f.name},
                        {"fmu", f.fmu},
                        {"fmi_version", f.fmi_version},
                        {"segment", f.segment},
                        {"step_ns", f.step.count()},
                        {"publishes", f.publishes()},
                        {"subscribes", f.subscribes()},
                        {"report", r ? report_json(*r, now) : Json(nullptr)},
                        {"overrun", why ? Json(*why) : Json(nullptr)}});
  }
  return Json{{"ok", true}, {"fmus", std::move(list)}};
}

Json FmuReports::channel_part(const std::string& channel, const std::vector<FmuSpec>& fmus,
                              Clock::time_point now) const {
  Json list = Json::array();
  for (const FmuSpec& f : fmus) {
    const bool publishes = names_contain(f.publishes(), channel);
    const bool subscribes = names_contain(f.subscribes(), channel);
    for (const bool publisher : {true, false}) {
      if (!(publisher ? publishes : subscribes)) continue;
      const FmuReport* r = find(f.name);
      const auto why = publisher ? overrun(f, now) : std::nullopt;  // only its outputs are flagged
      list.push_back(Json{{"name", f.name},
                          {"role", publisher ? "publisher" : "subscriber"},
                          {"segment", f.segment},
                          {"step_ns", f.step.count()},
                          {"report", r ? report_json(*r, now) : Json(nullptr)},
                          {"overrun", why ? Json(*why) : Json(nullptr)}});
    }
  }
  return list;
}

std::map<std::string, std::string> FmuReports::overruns(const std::vector<FmuSpec>& fmus, Clock::time_point now) const {
  std::map<std::string, std::string> out;
  for (const FmuSpec& f : fmus) {
    const auto why = overrun(f, now);
    if (!why) continue;
    for (const auto& channel : f.publishes()) {
      std::string& reasons = out[channel];
      reasons += (reasons.empty() ? "" : "; ") + *why;
    }
  }
  return out;
}

}  // namespace cosmic

#include "bind_answer.hpp"

#include <algorithm>

#include "cosmic/report.hpp"

namespace cosmic {

using Json = nlohmann::json;

Json failure(const std::string& code, const std::string& message) {
  return Json{{"ok", false}, {"error", {{"code", code}, {"message", message}}}};
}

std::string render(const Json& response) {
  return response.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

// A replacement's answer says per channel what changed and which hops stay (their endpoints and
// the subscribers behind them keep running), which are new and which are gone.
Json replaced_answer(const BindResult& result) {
  Json out = Json::array();
  for (const ReplacedChannel& replaced : result.replaced) {
    const ChannelSpec& before = replaced.before;
    const auto now = std::find_if(result.channels.begin(), result.channels.end(),
                                  [&](const ChannelReport& c) { return c.name == before.name; });
    Json hops{{"kept", Json::array()}, {"added", Json::array()}, {"removed", Json::array()}};
    std::vector<std::pair<std::string, HopRole>> old_hops;
    for (const auto& p : before.publishers) old_hops.emplace_back(p, HopRole::publisher);
    for (const auto& s : before.subscribers) old_hops.emplace_back(s, HopRole::subscriber);
    std::vector<std::pair<std::string, HopRole>> new_hops;
    if (now != result.channels.end()) {
      for (const auto& hop : now->hops) new_hops.emplace_back(hop.segment, hop.role);
    }
    auto hop_json = [](const std::pair<std::string, HopRole>& h) {
      return Json{{"segment", h.first}, {"role", to_string(h.second)}};
    };
    for (const auto& h : old_hops) {
      const bool kept = std::find(new_hops.begin(), new_hops.end(), h) != new_hops.end();
      hops[kept ? "kept" : "removed"].push_back(hop_json(h));
    }
    for (const auto& h : new_hops) {
      if (std::find(old_hops.begin(), old_hops.end(), h) == old_hops.end()) hops["added"].push_back(hop_json(h));
    }
    out.push_back({{"name", before.name}, {"changes", replaced.changes}, {"hops", std::move(hops)}});
  }
  return out;
}

Json bind_answer(const BindResult& result) {
  Json out{{"ok", result.applied}, {"applied", result.applied}, {"channels", Json::array()}};
  for (const auto& c : result.channels) out["channels"].push_back(to_json(c));
  const bool rejected = std::any_of(result.channels.begin(), result.channels.end(),
                                    [](const ChannelReport& c) { return c.verdict == Verdict::rejected; });
  if (!result.applied) out["error"] = {{"code", rejected ? "rejected" : "bind_failed"}, {"message", result.error}};
  return out;
}

Json switch_over_answer(const BindResult& result, Nanos match_timeout) {
  Json publishers = Json::array();
  for (const NewPublisher& p : result.new_publishers) {
    publishers.push_back(
        {{"channel", p.channel}, {"segment", p.segment}, {"matched", p.matched ? Json(*p.matched) : Json(nullptr)}});
  }
  return Json{{"waited_s", std::chrono::duration<double>(result.switch_wait).count()},
              {"match_timeout_s", std::chrono::duration<double>(match_timeout).count()},
              {"timed_out", result.match_timed_out},
              {"publishers", std::move(publishers)}};
}

}  // namespace cosmic

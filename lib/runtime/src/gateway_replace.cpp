// Gateway::replace (cosmicctl bind --replace): new definitions take the place of bound ones in one
// admission and one commit (the commit is commit_bind's).
#include <algorithm>

#include "cosmic/gateway.hpp"

namespace cosmic {

BindResult Gateway::replace(const std::vector<ChannelSpec>& channels) {
  BindPlan plan = replace_plan_input(channels);
  plan_replace(plan);
  return commit_bind(std::move(plan));
}

BindPlan Gateway::replace_plan_input(std::vector<ChannelSpec> channels) const {
  BindPlan plan = bind_plan_input(std::move(channels));
  plan.replacing = true;
  for (const auto& channel : plan.channels) {
    if (const ChannelSpec* bound = kb_->find_bound(channel.name)) plan.replaced.push_back(*bound);
  }
  return plan;
}

// The replaced channels all leave the copy before any new definition is admitted: each new one
// is judged against the set it will be part of, never against its own old reservation.
void Gateway::plan_replace(BindPlan& plan) {
  std::vector<std::string> unbound;
  for (const auto& channel : plan.channels) {
    if (!plan.kb->find_bound(channel.name)) unbound.push_back(channel.name);
  }
  if (!unbound.empty()) {
    std::string names;
    for (const auto& name : unbound) names += (names.empty() ? "" : ", ") + name;
    plan.admitted = false;
    for (const auto& channel : plan.channels) {
      const bool missing = std::find(unbound.begin(), unbound.end(), channel.name) != unbound.end();
      plan.reports.push_back(rejected_report(channel, missing ? "channel " + channel.name +
                                                                 " is not bound: there is nothing to replace (bind it instead)"
                                                           : "not replaced: the replacement names channels that are not bound (" +
                                                                 names + ")"));
    }
    return;
  }
  std::vector<std::optional<std::uint16_t>> etags;
  for (const auto& channel : plan.channels) {
    etags.push_back(plan.kb->etag_of(channel.name));
    plan.kb->unbind(channel.name);
  }
  plan.admitted = true;
  for (std::size_t c = 0; c < plan.channels.size(); ++c) {
    BindOutcome outcome = plan.kb->bind(plan.channels[c], etags[c]);
    plan.admitted = plan.admitted && outcome.bound();
    plan.reports.push_back(std::move(outcome.report));
  }
}

std::map<std::string, std::pair<ChannelSpec, ChannelId>> Gateway::take_over_ids(const std::vector<ChannelSpec>& channels) {
  std::map<std::string, std::pair<ChannelSpec, ChannelId>> previous;
  for (const auto& channel : channels) {
    const auto it = channel_ids_.find(channel.name);
    if (it == channel_ids_.end()) continue;  // never configured: id_for() gives it one
    previous.emplace(channel.name, it->second);
    it->second.first = channel;
  }
  return previous;
}

void Gateway::undo_takeover(std::map<std::string, std::pair<ChannelSpec, ChannelId>> previous) {
  for (auto& [name, entry] : previous) channel_ids_[name] = std::move(entry);
}

}  // namespace cosmic

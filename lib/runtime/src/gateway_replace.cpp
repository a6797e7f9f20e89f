// Gateway::replace (cosmicctl bind --replace): new definitions take the place of bound ones in one
// admission and one commit (the commit is commit_bind's), made before break: the hops on segments
// the channel did not use are opened first, and the switch waits for new publishers to match.
#include <algorithm>
#include <chrono>
#include <thread>

#include "cosmic/gateway.hpp"

namespace cosmic {

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
      plan.reports.push_back(rejected_report(
          channel, missing ? "channel " + channel.name + " is not bound: there is nothing to replace (bind it instead)"
                           : "not replaced: the replacement names channels that are not bound (" + names + ")"));
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

std::map<std::string, std::pair<ChannelSpec, ChannelId>> Gateway::take_over_ids(
    const std::vector<ChannelSpec>& channels) {
  std::map<std::string, std::pair<ChannelSpec, ChannelId>> previous;
  for (const auto& channel : channels) {
    const auto it = channel_ids_.find(channel.name);
    if (it == channel_ids_.end()) continue;  // never configured: id_for() gives it one
    previous.emplace(channel.name, it->second);
    it->second.first = channel;
  }
  return previous;
}

void Gateway::undo_takeover(std::map<std::string, std::pair<ChannelSpec, ChannelId>>&& previous) {
  for (auto& [name, entry] : previous) channel_ids_[name] = std::move(entry);
}

// --- make before break --------------------------------------------------------------------------

BindResult Gateway::replace(const std::vector<ChannelSpec>& channels, Nanos match_timeout) {
  BindPlan plan = replace_plan_input(channels);
  plan_replace(plan);
  const auto prepared_at = std::chrono::steady_clock::now();
  const bool timed_out = prepare_replace(plan) && !await_new_publishers(plan, prepared_at, match_timeout);
  return switch_over(std::move(plan), prepared_at, timed_out);
}

// No event loop here: polls the adapters' match counts (the control protocol polls from its
// worker instead when it has one, leaving the control thread free).
bool Gateway::await_new_publishers(const BindPlan& plan, std::chrono::steady_clock::time_point prepared_at,
                                   Nanos match_timeout) const {
  while (!all_matched(new_publishers(plan))) {
    if (std::chrono::steady_clock::now() - prepared_at >= match_timeout) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// Only segments where the channel has no hop at all: a hop that changes role on a segment the
// channel keeps (one endpoint set per channel there) changes at the switch, as before.
std::multimap<std::string, ChannelBinding> Gateway::added_hops(const BindPlan& plan) const {
  std::multimap<std::string, ChannelBinding> added;
  const AdmissionReport report = plan.kb->report();
  for (const auto& channel : plan.channels) {
    const auto id = channel_ids_.find(channel.name);
    const ChannelSpec* before = kb_->find_bound(channel.name);
    const ChannelReport* verdict = report.find(channel.name);
    if (id == channel_ids_.end() || !before || !verdict) continue;  // never configured: opened at the switch
    auto uses = [&](const std::string& segment) {
      return std::find(before->publishers.begin(), before->publishers.end(), segment) != before->publishers.end() ||
             std::find(before->subscribers.begin(), before->subscribers.end(), segment) != before->subscribers.end();
    };
    for (const auto& hop : verdict->hops) {
      if (!uses(hop.segment)) added.emplace(hop.segment, ChannelBinding{id->second.second, channel, hop.role, hop.can});
    }
  }
  return added;
}

bool Gateway::prepare_replace(const BindPlan& plan) {
  if (!plan.replacing || !plan.admitted || plan.generation != generation_) return false;
  const auto added = added_hops(plan);
  if (added.empty()) return false;
  prepared_ = true;
  const Refusals refusals = configure_adapters(added);
  for (const auto& [segment, binding] : added) {
    const auto channel = refusals.find(binding.spec.name);
    if (channel != refusals.end() && channel->second.count(segment)) {
      prepared_ = false;
      configure_adapters();  // the commit meets the same refusal and reports it
      return false;
    }
  }
  return true;
}

std::vector<NewPublisher> Gateway::new_publishers(const BindPlan& plan) const {
  std::vector<NewPublisher> found;
  for (const auto& channel : plan.channels) {
    const auto before = std::find_if(plan.replaced.begin(), plan.replaced.end(),
                                     [&](const ChannelSpec& c) { return c.name == channel.name; });
    for (const auto& segment : channel.publishers) {
      const bool kept = before != plan.replaced.end() && std::find(before->publishers.begin(), before->publishers.end(),
                                                                   segment) != before->publishers.end();
      if (!kept) found.push_back(NewPublisher{channel.name, segment, matched_peers(segment, channel.name)});
    }
  }
  return found;
}

bool Gateway::all_matched(const std::vector<NewPublisher>& publishers) {
  return std::all_of(publishers.begin(), publishers.end(),
                     [](const NewPublisher& p) { return !p.matched || *p.matched > 0; });
}

BindResult Gateway::switch_over(BindPlan plan, std::chrono::steady_clock::time_point prepared_at, bool timed_out) {
  std::vector<NewPublisher> publishers = new_publishers(plan);
  BindResult result = commit_bind(std::move(plan));
  if (!result.applied) return result;
  result.new_publishers = std::move(publishers);
  result.switch_wait = std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now() - prepared_at);
  result.match_timed_out = timed_out;
  return result;
}

}  // namespace cosmic

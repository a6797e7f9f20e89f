#include "cosmic/gateway.hpp"

#include "cosmic/can_buffering.hpp"
#include "cosmic/channel_changes.hpp"
#include "cosmic/hop_representation.hpp"

#include <algorithm>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_map>
#include <utility>

namespace cosmic {

Gateway::Gateway(AdapterFactory factory, Logger& log, std::uint64_t gateway_id)
    : factory_(std::move(factory)), log_(log), identity_{gateway_id, {}} {}

Gateway::~Gateway() { stop(); }

namespace {

// Whether admitting `config` from scratch passes through the state admitting `base` left: the
// same knowledge base to start from, and `base`'s channels bound first, in the same order.
bool extends(const Config& config, const Config& base) {
  return config.gateway == base.gateway && config.segments == base.segments &&
         config.channels.size() >= base.channels.size() &&
         std::equal(base.channels.begin(), base.channels.end(), config.channels.begin()) &&
         reserved_etags(config) == reserved_etags(base);
}

}  // namespace

std::unique_ptr<KnowledgeBase> Gateway::knowledge_base_for(const Config& config) {
  return std::make_unique<KnowledgeBase>(config.gateway, config.segments, reserved_etags(config));
}

std::size_t Gateway::free_slot(const std::set<std::size_t>& also_taken) const {
  for (std::size_t i = 0; i < kMaxSegments; ++i) {
    const bool used = also_taken.count(i) > 0 ||
                      std::any_of(slots_.begin(), slots_.end(), [&](const auto& s) { return s.second.index == i; });
    if (!used) return i;
  }
  return kMaxSegments;
}

ChannelId Gateway::id_for(const ChannelSpec& spec) {
  auto it = channel_ids_.find(spec.name);
  if (it != channel_ids_.end() && it->second.first == spec) return it->second.second;
  const ChannelId id = next_channel_id_++;
  channel_ids_[spec.name] = {spec, id};
  return id;
}

BindResult Gateway::start(const Config& config) {
  identity_.name = config.gateway.name;
  const RouterLimits limits = router_limits(config.gateway);
  router_ = std::make_unique<Router>(identity_, kMaxSegments, limits);
  router_->set_record_hook(record_hook_);
  router_->select_recorded(record_selection_);
  const ThreadPolicy receive{"rx", config.gateway.realtime.receive_priority, 0, config.gateway.realtime.cpus.receive};
  for (std::size_t i = 0; i < kMaxSegments; ++i) {
    EventSink& inbox = router_->inbox(i);
    inbox.set_receive_thread_policy(receive);
    for (const ChannelClass cls : {ChannelClass::hrt, ChannelClass::srt, ChannelClass::nrt}) {
      inbox.set_class_thread_policy(cls, limits.lane_threads[static_cast<std::size_t>(cls)]);
    }
  }
  config_ = config;
  kb_ = knowledge_base_for(config);
  BindResult result;
  for (const auto& spec : config.segments) {
    SegmentSlot slot{free_slot(), spec, factory_(spec, identity_, log_), {}};
    if (!slot.adapter || slot.index >= kMaxSegments) {
      result.error = "cannot create the adapter of segment " + spec.name;
      stop();
      return result;
    }
    router_->set_segment(slot.index, spec.name, slot.adapter.get(), egress_lane_floor(spec));
    const Status started = slot.adapter->start(router_->inbox(slot.index));
    if (!started.ok) log_.log(LogLevel::error, "segment " + spec.name + " did not start: " + started.error);
    slots_.emplace(spec.name, std::move(slot));
  }
  for (const auto& channel : config.channels) {
    BindOutcome outcome = kb_->bind(channel);
    if (!outcome.bound()) {
      std::string why;
      for (const auto& r : outcome.report.reasons) why += (why.empty() ? "" : "; ") + r;
      log_.log(LogLevel::warning, "channel " + channel.name + " rejected: " + why);
    }
    result.channels.push_back(std::move(outcome.report));
  }
  base_ = std::make_shared<const ReloadBase>(ReloadBase{config, *kb_, result.channels});
  base_generation_ = generation_;
  configure_adapters();
  for (auto& report : result.channels) mark_refused(report);
  apply_routes();
  result.applied = true;
  return result;
}

Gateway::Refusals Gateway::configure_adapters(const std::multimap<std::string, ChannelBinding>& extra) {
  const AdmissionReport report = kb_->report();
  std::unordered_map<std::string_view, const ChannelReport*> verdicts;
  verdicts.reserve(report.channels.size());
  for (const auto& verdict : report.channels) verdicts.emplace(verdict.name, &verdict);
  Refusals refusals;
  for (auto& [name, slot] : slots_) {
    std::vector<ChannelBinding> bindings;
    for (const auto& channel : kb_->bound_channels()) {
      const auto found = verdicts.find(channel.name);
      if (found == verdicts.end()) continue;
      for (const auto& hop : found->second->hops) {
        if (hop.segment == name) bindings.push_back(ChannelBinding{id_for(channel), channel, hop.role, hop.can});
      }
    }
    for (auto [it, end] = extra.equal_range(name); it != end; ++it) bindings.push_back(it->second);
    const Status status = slot.adapter->configure(bindings);
    std::set<std::pair<ChannelId, HopRole>> given;
    for (const auto& b : bindings) given.emplace(b.id, b.role);
    if (status.ok) {
      slot.carried = std::move(given);
      continue;
    }
    // Which channels the failure concerns: those the adapter names, else every binding it was
    // not already known to carry (an adapter that fails as a whole keeps at most what it had).
    std::map<ChannelId, std::string> why;
    for (const auto& refusal : status.refused) why.emplace(refusal.channel, refusal.reason);
    std::set<std::pair<ChannelId, HopRole>> carried;
    for (const auto& b : bindings) {
      const bool was_carried = slot.carried.count({b.id, b.role}) > 0;
      if (status.refused.empty() && !was_carried) why.emplace(b.id, status.error);
      if (!why.count(b.id) && (was_carried || !status.refused.empty())) carried.emplace(b.id, b.role);
    }
    slot.carried = std::move(carried);
    bool named = false;
    for (const auto& b : bindings) {
      const auto reason = why.find(b.id);
      if (reason == why.end()) continue;
      refusals[b.spec.name].emplace(name, reason->second);
      named = true;
    }
    if (!named) {
      // Nothing bound here is affected (the adapter still carries every binding it was given).
      log_.log(LogLevel::error, "segment " + name + ": configuring its channels failed: " + status.error +
                                    " (every channel bound there is still carried)");
    }
  }
  // One line per channel and segment when a refusal starts or its reason changes, one when it ends.
  for (const auto& [channel, segments] : refusals) {
    const auto before = refused_.find(channel);
    for (const auto& [segment, reason] : segments) {
      if (before != refused_.end()) {
        const auto same = before->second.find(segment);
        if (same != before->second.end() && same->second == reason) continue;
      }
      log_.log(LogLevel::error,
               "channel " + channel + ": segment " + segment + " does not carry it: " + reason + " (verdict failed)");
    }
  }
  for (const auto& [channel, segments] : refused_) {
    if (!kb_->find_bound(channel)) continue;
    const auto now = refusals.find(channel);
    for (const auto& [segment, reason] : segments) {
      if (now != refusals.end() && now->second.count(segment)) continue;
      if (slots_.count(segment))
        log_.log(LogLevel::notice, "channel " + channel + ": segment " + segment + " carries it now");
    }
  }
  refused_ = refusals;
  return refusals;
}

void Gateway::mark_refused(ChannelReport& report) const {
  const auto refused = refused_.find(report.name);
  if (refused == refused_.end()) return;
  report.verdict = Verdict::failed;
  for (const auto& [segment, reason] : refused->second) {
    report.reasons.push_back("segment " + segment + " does not carry it: " + reason);
  }
}

AdmissionReport Gateway::admission() const {
  AdmissionReport report = kb_->report();
  if (!refused_.empty()) {
    for (auto& channel : report.channels) mark_refused(channel);
  }
  return report;
}

Gateway::VerdictCounts Gateway::verdict_counts() const {
  VerdictCounts counts;
  for (const auto& c : admission().channels) {
    counts.bound += c.verdict == Verdict::bound ? 1 : 0;
    counts.degraded += c.verdict == Verdict::degraded ? 1 : 0;
    counts.failed += c.verdict == Verdict::failed ? 1 : 0;
  }
  return counts;
}

void Gateway::apply_routes() {
  std::vector<Route> routes;
  hop_forms_.clear();
  for (const auto& channel : kb_->bound_channels()) {
    Route route{id_for(channel), channel, {}, {}};
    for (const auto& p : channel.publishers) {
      route.publishers.push_back(slots_.at(p).index);
      if (const SegmentSpec* segment = config_.find_segment(p)) {
        route.ingress_jitter = std::max(route.ingress_jitter, ip_hop_latency(*segment));
      }
    }
    for (const auto& s : channel.subscribers) route.subscribers.push_back(slots_.at(s).index);
    if (channel.type && !add_representations(route)) continue;
    routes.push_back(std::move(route));
  }
  if (!on_routes_) {
    router_->apply(std::move(routes));
    return;
  }
  router_->apply(routes);
  on_routes_(routes);
}

void Gateway::set_recording(RecordHook* hook, std::function<bool(const ChannelSpec&)> selects,
                            RouteObserver on_routes) {
  record_hook_ = hook;
  record_selection_ = std::move(selects);
  on_routes_ = std::move(on_routes);
  if (!router_) return;
  router_->set_record_hook(record_hook_);
  router_->select_recorded(record_selection_);
  apply_routes();  // the same table again (no channel's state changes), shown to the observer
}

void Gateway::select_recorded(std::function<bool(const ChannelSpec&)> selects) {
  record_selection_ = std::move(selects);
  if (router_) router_->select_recorded(record_selection_);
}

// Each hop's representation of a typed channel. Admission has rejected a channel with a hop that
// cannot carry the type (check "representation"), so a failure here means the segment changed
// under the channel: the channel is not routed (its events count as unrouted), never forwarded in
// a form its hop does not take.
bool Gateway::add_representations(Route& route) {
  const auto form_on = [&](const std::string& name) -> std::shared_ptr<const Representation> {
    const SegmentSpec* segment = config_.find_segment(name);
    if (segment == nullptr) return nullptr;
    Result<std::shared_ptr<const Representation>> made = hop_representation(route.spec, *segment);
    if (!made) {
      log_.log(LogLevel::error,
               "channel " + route.spec.name + " not routed: segment " + name + ": " + made.error().text);
      return nullptr;
    }
    return made.value();
  };
  for (const auto& p : route.spec.publishers) {
    route.publisher_forms.push_back(form_on(p));
    if (!route.publisher_forms.back()) return false;
  }
  for (const auto& s : route.spec.subscribers) {
    route.subscriber_forms.push_back(form_on(s));
    if (!route.subscriber_forms.back()) return false;
  }
  auto& forms = hop_forms_[route.spec.name];
  for (std::size_t i = 0; i < route.spec.publishers.size(); ++i)
    forms[route.spec.publishers[i]] = route.publisher_forms[i]->describe();
  for (std::size_t i = 0; i < route.spec.subscribers.size(); ++i)
    forms[route.spec.subscribers[i]] = route.subscriber_forms[i]->describe();
  return true;
}

std::optional<std::string> Gateway::hop_form(const std::string& channel, const std::string& segment) const {
  const auto forms = hop_forms_.find(channel);
  if (forms == hop_forms_.end()) return std::nullopt;
  const auto form = forms->second.find(segment);
  return form == forms->second.end() ? std::nullopt : std::optional<std::string>(form->second);
}

BindResult Gateway::bind(const std::vector<ChannelSpec>& channels) {
  BindPlan plan = bind_plan_input(channels);
  plan_bind(plan);
  return commit_bind(std::move(plan));
}

BindPlan Gateway::bind_plan_input(std::vector<ChannelSpec> channels) const {
  return BindPlan{generation_, std::move(channels), std::make_shared<KnowledgeBase>(*kb_), {}, false, false, {}};
}

void Gateway::plan_bind(BindPlan& plan) {
  plan.admitted = true;
  for (const auto& channel : plan.channels) {
    BindOutcome outcome = plan.kb->bind(channel);
    plan.admitted = plan.admitted && outcome.bound();
    plan.reports.push_back(std::move(outcome.report));
  }
}

BindResult Gateway::commit_bind(BindPlan plan) {
  // A replacement's hops opened by prepare_replace() close again unless this commit keeps them.
  const bool prepared = std::exchange(prepared_, false);
  BindResult result = commit_plan(std::move(plan));
  if (prepared && !result.applied) configure_adapters();
  return result;
}

BindResult Gateway::commit_plan(BindPlan plan) {
  BindResult result;
  result.channels = std::move(plan.reports);
  const auto& channels = plan.channels;
  for (auto& before : plan.replaced) {
    const auto now =
        std::find_if(channels.begin(), channels.end(), [&](const ChannelSpec& c) { return c.name == before.name; });
    std::vector<std::string> changes =
        now != channels.end() ? definition_changes(before, *now) : std::vector<std::string>{};
    result.replaced.push_back(ReplacedChannel{std::move(before), std::move(changes)});
  }
  if (plan.generation != generation_) {
    result.error = "the bindings changed while admission ran; nothing changed, try again";
    return result;
  }
  if (!plan.admitted) {
    result.error = "rejected by admission; nothing changed";
    return result;
  }
  ++generation_;
  KnowledgeBase previous = *kb_;
  *kb_ = std::move(*plan.kb);
  // Replaced channels keep their ids, so the adapters see changed bindings, not new channels.
  auto ids_before = plan.replacing ? take_over_ids(channels) : decltype(take_over_ids(channels)){};
  // A segment refusing one of the new channels undoes the whole bind; refusals of channels
  // bound before are theirs to show and do not block it.
  const Refusals refusals = configure_adapters();
  std::string refused;
  for (auto& report : result.channels) {
    const auto found = refusals.find(report.name);
    if (found == refusals.end()) continue;
    mark_refused(report);
    for (const auto& [segment, reason] : found->second) {
      refused += (refused.empty() ? "" : "; ") +
                 ("segment " + segment + " does not carry channel " + report.name + ": " + reason);
    }
  }
  if (!refused.empty()) {
    *kb_ = std::move(previous);
    if (plan.replacing) undo_takeover(std::move(ids_before));
    configure_adapters();
    result.error = refused + "; nothing changed";
    return result;
  }
  apply_routes();
  if (!plan.replacing) {
    for (const auto& channel : channels) log_.log(LogLevel::notice, "bound channel " + channel.name);
  }
  for (const auto& replaced : result.replaced) {
    std::string changes;
    for (const auto& change : replaced.changes) changes += (changes.empty() ? "" : "; ") + change;
    log_.log(LogLevel::notice, "replaced the definition of channel " + replaced.before.name + " (" +
                                   (changes.empty() ? std::string("unchanged") : changes) + ")");
  }
  result.applied = true;
  return result;
}

namespace {
// The identifier of every bound channel's CAN hops, in report order.
std::vector<std::uint32_t> can_identifiers(const KnowledgeBase& kb) {
  std::vector<std::uint32_t> ids;
  for (const ChannelReport& channel : kb.report().channels) {
    for (const HopReport& hop : channel.hops) {
      if (hop.can) ids.push_back(hop.can->can_id);
    }
  }
  return ids;
}
}  // namespace

void Gateway::set_peer_reservations(PeerNetworks peers) {
  if (peers == kb_->peer_reservations()) return;
  const auto ids_before = can_identifiers(*kb_);
  kb_->set_peer_reservations(std::move(peers));
  ++generation_;  // a bind planned without them is planned again
  // The analysis from scratch may spread a bus's priorities afresh (after unbinds kept them).
  if (router_ && can_identifiers(*kb_) != ids_before) {
    configure_adapters();
    apply_routes();
  }
}

bool Gateway::unbind(const std::string& name) {
  if (!kb_->unbind(name)) return false;
  ++generation_;
  apply_routes();
  configure_adapters();
  log_.log(LogLevel::notice, "unbound channel " + name);
  return true;
}

BindResult Gateway::reload(const Config& config) { return commit_reload(plan_reload(config)); }

ReloadPlan Gateway::plan_reload(Config config, std::shared_ptr<const ReloadBase> base, PeerNetworks peers) {
  ReloadPlan plan;
  const bool from_base = base && extends(config, base->config) && base->kb.peer_reservations() == peers;
  if (from_base) {
    plan.kb = std::make_shared<KnowledgeBase>(base->kb);
    plan.reports = base->reports;
    plan.reused = base->config.channels.size();
  } else {
    plan.kb = knowledge_base_for(config);
    plan.kb->set_peer_reservations(std::move(peers));
  }
  plan.config = std::move(config);
  for (std::size_t c = plan.reused; c < plan.config.channels.size(); ++c) {
    plan.reports.push_back(plan.kb->bind(plan.config.channels[c]).report);
  }
  const bool unchanged = from_base && plan.reused == plan.config.channels.size();
  plan.admitted =
      unchanged ? std::move(base) : std::make_shared<const ReloadBase>(ReloadBase{plan.config, *plan.kb, plan.reports});
  return plan;
}

const ChannelReport* Gateway::rejected_at_load(const std::string& name) const {
  if (!base_ || kb_->find_bound(name)) return nullptr;
  const auto& reports = base_->reports;
  const auto found =
      std::find_if(reports.begin(), reports.end(), [&](const ChannelReport& r) { return r.name == name; });
  return found != reports.end() && found->verdict == Verdict::rejected ? &*found : nullptr;
}

std::shared_ptr<const ReloadBase> Gateway::reload_base() const {
  return generation_ == base_generation_ ? base_ : nullptr;
}

BindResult Gateway::commit_reload(ReloadPlan plan) {
  const Config& config = plan.config;
  BindResult result;
  result.channels = std::move(plan.reports);
  auto next_kb = std::make_unique<KnowledgeBase>(std::move(*plan.kb));
  ++generation_;
  // New or changed segments get fresh adapters in free slots; the old ones keep running until
  // the swap below.
  std::map<std::string, SegmentSlot> fresh;
  for (const auto& spec : config.segments) {
    const auto running = slots_.find(spec.name);
    if (running != slots_.end() && running->second.spec == spec) continue;
    std::set<std::size_t> taken;
    for (const auto& [n, s] : fresh) taken.insert(s.index);
    const std::size_t index = free_slot(taken);
    SegmentSlot slot{index, spec, index < kMaxSegments ? factory_(spec, identity_, log_) : nullptr, {}};
    if (!slot.adapter) {
      for (auto& [n, s] : fresh) {
        s.adapter->stop();
        router_->set_segment(s.index, "", nullptr);
      }
      result.error = "cannot create the adapter of segment " + spec.name + "; running configuration kept";
      return result;
    }
    router_->set_segment(slot.index, spec.name, slot.adapter.get(), egress_lane_floor(spec));
    const Status started = slot.adapter->start(router_->inbox(slot.index));
    if (!started.ok) log_.log(LogLevel::error, "segment " + spec.name + " did not start: " + started.error);
    fresh.emplace(spec.name, std::move(slot));
  }
  std::vector<SegmentSlot> retired;
  for (auto it = slots_.begin(); it != slots_.end();) {
    const auto* spec = config.find_segment(it->first);
    if (spec && *spec == it->second.spec) {
      ++it;
      continue;
    }
    retired.push_back(std::move(it->second));
    it = slots_.erase(it);
  }
  for (auto& [name, slot] : fresh) slots_.emplace(name, std::move(slot));
  if (config.gateway.control_socket != config_.gateway.control_socket) {
    log_.log(LogLevel::warning, "gateway.control_socket changes take effect at the next start");
  }
  if (config.gateway.realtime != config_.gateway.realtime) {
    log_.log(LogLevel::warning, "gateway.realtime changes take effect at the next start");
  }
  // Admission of the new configuration used its residence_bound: the lanes check that one.
  router_->set_residence_bound(config.gateway.residence_bound);
  config_ = config;
  identity_.name = config.gateway.name;
  // Other gateways' reservations that changed while the plan was made (no-op otherwise).
  next_kb->set_peer_reservations(kb_->peer_reservations());
  kb_ = std::move(next_kb);
  // As in bind(): adapters carry the new channels before the router sends to them.
  configure_adapters();
  for (auto& report : result.channels) mark_refused(report);
  apply_routes();
  for (auto& slot : retired) {
    router_->set_segment(slot.index, "", nullptr);
    slot.adapter->stop();
  }
  base_ = std::move(plan.admitted);
  base_generation_ = generation_;
  log_.log(LogLevel::notice,
           "configuration reloaded" +
               (plan.reused > 0 ? " (" + std::to_string(plan.reused) + " unchanged channels kept their admission)"
                                : std::string()));
  result.applied = true;
  return result;
}

void Gateway::stop() {
  if (router_) router_->stop();
  for (auto& [name, slot] : slots_) {
    if (router_) router_->set_segment(slot.index, "", nullptr);
    slot.adapter->stop();
  }
  slots_.clear();
}

}  // namespace cosmic

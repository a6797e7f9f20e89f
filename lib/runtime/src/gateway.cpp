#include "cosmic/gateway.hpp"

#include <algorithm>
#include <set>

namespace cosmic {

Gateway::Gateway(AdapterFactory factory, Logger& log, std::uint64_t gateway_id)
    : factory_(std::move(factory)), log_(log), identity_{gateway_id, {}} {}

Gateway::~Gateway() { stop(); }

std::unique_ptr<KnowledgeBase> Gateway::knowledge_base_for(const Config& config) {
  std::set<std::uint16_t> reserved;
  for (const auto& channel : config.channels) {
    if (channel.etag) reserved.insert(*channel.etag);
  }
  return std::make_unique<KnowledgeBase>(config.gateway, config.segments, reserved);
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
  router_ = std::make_unique<Router>(identity_, kMaxSegments);
  config_ = config;
  kb_ = knowledge_base_for(config);
  BindResult result;
  for (const auto& spec : config.segments) {
    SegmentSlot slot{free_slot(), spec, factory_(spec, identity_, log_)};
    if (!slot.adapter || slot.index >= kMaxSegments) {
      result.error = "cannot create the adapter of segment " + spec.name;
      stop();
      return result;
    }
    router_->set_segment(slot.index, spec.name, slot.adapter.get());
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
  if (auto error = configure_adapters()) log_.log(LogLevel::error, *error);
  apply_routes();
  router_thread_ = std::thread([this] { router_->run(); });
  result.applied = true;
  return result;
}

std::optional<std::string> Gateway::configure_adapters() {
  const AdmissionReport report = kb_->report();
  std::optional<std::string> first_error;
  for (auto& [name, slot] : slots_) {
    std::vector<ChannelBinding> bindings;
    for (const auto& channel : kb_->bound_channels()) {
      const ChannelReport* verdict = report.find(channel.name);
      if (!verdict) continue;
      for (const auto& hop : verdict->hops) {
        if (hop.segment == name) bindings.push_back(ChannelBinding{id_for(channel), channel, hop.role, hop.can});
      }
    }
    const Status status = slot.adapter->configure(bindings);
    if (!status.ok && !first_error) first_error = "segment " + name + ": " + status.error;
  }
  return first_error;
}

void Gateway::apply_routes() {
  std::vector<Route> routes;
  for (const auto& channel : kb_->bound_channels()) {
    Route route{id_for(channel), channel, {}, {}};
    for (const auto& p : channel.publishers) route.publishers.push_back(slots_.at(p).index);
    for (const auto& s : channel.subscribers) route.subscribers.push_back(slots_.at(s).index);
    routes.push_back(std::move(route));
  }
  router_->apply(std::move(routes));
}

BindResult Gateway::bind(const std::vector<ChannelSpec>& channels) {
  BindResult result;
  KnowledgeBase trial = *kb_;
  bool rejected = false;
  for (const auto& channel : channels) {
    BindOutcome outcome = trial.bind(channel);
    rejected = rejected || !outcome.bound();
    result.channels.push_back(std::move(outcome.report));
  }
  if (rejected) {
    result.error = "rejected by admission; nothing changed";
    return result;
  }
  KnowledgeBase previous = *kb_;
  *kb_ = std::move(trial);
  if (auto error = configure_adapters()) {
    *kb_ = std::move(previous);
    configure_adapters();
    result.error = *error + "; nothing changed";
    return result;
  }
  apply_routes();
  for (const auto& channel : channels) log_.log(LogLevel::notice, "bound channel " + channel.name);
  result.applied = true;
  return result;
}

bool Gateway::unbind(const std::string& name) {
  if (!kb_->unbind(name)) return false;
  apply_routes();
  if (auto error = configure_adapters()) log_.log(LogLevel::error, *error);
  log_.log(LogLevel::notice, "unbound channel " + name);
  return true;
}

BindResult Gateway::reload(const Config& config) {
  BindResult result;
  auto next_kb = knowledge_base_for(config);
  for (const auto& channel : config.channels) result.channels.push_back(next_kb->bind(channel).report);
  // New or changed segments get fresh adapters in free slots; the old ones keep running until
  // the swap below.
  std::map<std::string, SegmentSlot> fresh;
  for (const auto& spec : config.segments) {
    const auto running = slots_.find(spec.name);
    if (running != slots_.end() && running->second.spec == spec) continue;
    std::set<std::size_t> taken;
    for (const auto& [n, s] : fresh) taken.insert(s.index);
    const std::size_t index = free_slot(taken);
    SegmentSlot slot{index, spec, index < kMaxSegments ? factory_(spec, identity_, log_) : nullptr};
    if (!slot.adapter) {
      for (auto& [n, s] : fresh) {
        s.adapter->stop();
        router_->set_segment(s.index, "", nullptr);
      }
      result.error = "cannot create the adapter of segment " + spec.name + "; running configuration kept";
      return result;
    }
    router_->set_segment(slot.index, spec.name, slot.adapter.get());
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
  config_ = config;
  identity_.name = config.gateway.name;
  kb_ = std::move(next_kb);
  // As in bind(): adapters carry the new channels before the router sends to them.
  if (auto error = configure_adapters()) log_.log(LogLevel::error, *error);
  apply_routes();
  for (auto& slot : retired) {
    router_->set_segment(slot.index, "", nullptr);
    slot.adapter->stop();
  }
  log_.log(LogLevel::notice, "configuration reloaded");
  result.applied = true;
  return result;
}

void Gateway::stop() {
  if (router_) router_->stop();
  if (router_thread_.joinable()) router_thread_.join();
  for (auto& [name, slot] : slots_) {
    if (router_) router_->set_segment(slot.index, "", nullptr);
    slot.adapter->stop();
  }
  slots_.clear();
}

void Gateway::refresh_health() {
  for (const auto& [name, slot] : slots_) {
    HealthReport health = slot.adapter->health();
    kb_->set_health(name, health.state, std::move(health.detail));
  }
}

std::optional<std::size_t> Gateway::matched_peers(const std::string& segment, const std::string& channel) const {
  const auto slot = slots_.find(segment);
  const auto id = channel_ids_.find(channel);
  if (slot == slots_.end() || id == channel_ids_.end()) return std::nullopt;
  return slot->second.adapter->matched_peers(id->second.second);
}

bool Gateway::all_segments_up() const {
  return std::all_of(slots_.begin(), slots_.end(),
                     [](const auto& s) { return s.second.adapter->health().state == SegmentHealth::up; });
}

std::vector<SegmentInfo> Gateway::segments() const {
  const AdmissionReport report = kb_->report();
  std::vector<SegmentInfo> out;
  for (const auto& spec : config_.segments) {
    const auto slot = slots_.find(spec.name);
    if (slot == slots_.end()) continue;
    SegmentInfo info{spec, slot->second.adapter->health(), slot->second.adapter->statistics(), 0, 0,
                     router_->unrouted(slot->second.index)};
    for (const auto& load : report.segments) {
      if (load.name == spec.name) info.utilization = load.utilization;
    }
    for (const auto& channel : report.channels) {
      info.channels += static_cast<std::size_t>(std::count_if(channel.hops.begin(), channel.hops.end(),
                                                              [&](const auto& h) { return h.segment == spec.name; }));
    }
    out.push_back(std::move(info));
  }
  return out;
}

}  // namespace cosmic

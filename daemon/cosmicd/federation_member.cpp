#include "federation_member.hpp"

namespace cosmicd {
namespace {

// Lost and left peers stay listed this many leases, then are forgotten.
constexpr int kForgetAfterLeases = 20;
// Writers refused by the link that are each logged once; beyond, their refusals are logged as others are.
constexpr std::size_t kMaxRefusedWritersLogged = 1024;

double seconds_between(cosmic::Nanos from, cosmic::Nanos to) {
  return std::chrono::duration<double>(to - from).count();
}

}  // namespace

FederationMember::FederationMember(cosmic::Gateway& gateway, cosmic::Logger& log, FederationLinkFactory factory)
    : gateway_(gateway), log_(log), factory_(std::move(factory)) {}

FederationMember::~FederationMember() {
  if (link_) link_->withdraw();
}

void FederationMember::leave() {
  claim_.reset();
  if (link_) link_->withdraw();
  link_.reset();
  view_.reset();
  announced_.reset();
  gateway_.set_peer_reservations({});
}

void FederationMember::follow_configuration() {
  const cosmic::Config& config = gateway_.config();
  const cosmic::FederationSpec& spec = config.gateway.federation;
  const cosmic::SegmentSpec* segment = spec.enabled() ? config.find_segment(spec.segment) : nullptr;
  const cosmic::SegmentSpec wanted = segment ? *segment : cosmic::SegmentSpec{};
  if (spec == spec_ && wanted == segment_ && (link_ || !spec.enabled() || !start_error_.empty())) return;
  if (link_) {
    log_.log(cosmic::LogLevel::notice, "federation: leaving (over segment " + spec_.segment + ")");
    end_claim();  // the claim is void: the bind commits against what is known
    leave();
  }
  spec_ = spec;
  segment_ = wanted;
  start_error_.clear();
  if (!segment) return;
  auto link = factory_(*segment, gateway_.identity(), spec, log_);
  if (const std::string error = link->start(); !error.empty()) {
    start_error_ = error;
    log_.log(cosmic::LogLevel::error, "federation: cannot join over segment " + spec.segment + ": " + error +
                                          "; this gateway admits as if alone");
    return;
  }
  link_ = std::move(link);
  view_ = std::make_unique<cosmic::FederationView>(gateway_.identity().id);
  announced_generation_ = UINT64_MAX;
  log_.log(cosmic::LogLevel::notice, "federation: joined over segment " + spec.segment + " (DDS domain " +
                                         std::to_string(segment->dds.domain) + ", lease " +
                                         cosmic::format_duration(spec.lease) + ")");
}

void FederationMember::log_transitions(const std::map<std::uint64_t, cosmic::PeerState>& before) {
  for (const auto& [id, peer] : view_->peers()) {
    const auto was = before.find(id);
    if (was != before.end() && was->second == peer.state) continue;
    const std::string who = "gateway " + peer.announcement.name + " (" + cosmic::gateway_id_text(id) + ")";
    if (peer.state == cosmic::PeerState::alive) {
      log_.log(cosmic::LogLevel::notice, "federation: " + who + (was == before.end() ? " joined" : " is back") +
                                             " with " + std::to_string(peer.announcement.segments.size()) +
                                             " segments and " + std::to_string(peer.announcement.channels.size()) +
                                             " channels");
    } else {
      log_.log(cosmic::LogLevel::warning,
               "federation: " + who + (peer.state == cosmic::PeerState::left ? " left" : " was lost (lease expired)") +
                   "; its reservations are released");
    }
  }
}

// What the other gateways now reserve or send changed a local channel's verdict: say so, with why.
void FederationMember::log_verdict_changes(const cosmic::AdmissionReport& was, const cosmic::AdmissionReport& now) {
  for (const cosmic::ChannelReport& channel : now.channels) {
    const cosmic::ChannelReport* before = was.find(channel.name);
    if (!before || (before->verdict == channel.verdict && before->reasons == channel.reasons &&
                    before->end_to_end.latency == channel.end_to_end.latency)) {
      continue;
    }
    std::string line = "federation: channel " + channel.name + " is " + cosmic::to_string(channel.verdict) + " (was " +
                       cosmic::to_string(before->verdict) + ")";
    line += ", end to end " + (channel.end_to_end.latency ? cosmic::format_duration(*channel.end_to_end.latency)
                                                          : std::string("unbounded"));
    if (!channel.upstream.empty()) line += " through gateway " + channel.upstream.front().gateway;
    for (const auto& reason : channel.reasons) line += "; " + reason;
    log_.log(channel.verdict == cosmic::Verdict::bound ? cosmic::LogLevel::notice : cosmic::LogLevel::warning, line);
  }
}

void FederationMember::hear(cosmic::Nanos now) {
  std::map<std::uint64_t, cosmic::PeerState> before;
  for (const auto& [id, peer] : view_->peers()) before[id] = peer.state;
  bool changed = false;
  std::string refusal;
  for (const cosmic::FederationMessage& message : link_->take()) {
    changed |= view_->apply(message, now, &refusal);
    // Its sender's handshake is slow: reported once per waiting announcement, which may still count.
    if (message.awaiting_authentication) {
      log_.log(cosmic::LogLevel::warning, "federation: gateway " + cosmic::gateway_id_text(message.key) + ": " +
                                              message.refusal + "; counted as refused until then");
      continue;
    }
    // A gateway the link refuses (authenticated, not listed) is logged once, with its subject.
    if (!message.refusal.empty() && refused_writers_logged_.size() < kMaxRefusedWritersLogged) {
      if (refused_writers_logged_.insert(message.source).second) {
        log_.log(cosmic::LogLevel::warning, "federation: ignoring gateway " + cosmic::gateway_id_text(message.key) +
                                                ": " + message.refusal +
                                                "; its announcements are refused and counted (logged once)");
      }
      continue;
    }
    // A hostile or broken peer may repeat itself: the first refusals are logged, then every 1000th.
    if (!refusal.empty() && (refusals_logged_++ < 10 || refusals_logged_ % 1000 == 0)) {
      log_.log(cosmic::LogLevel::warning, "federation: refused an announcement: " + refusal + " (" +
                                              std::to_string(view_->counters().refused) + " refused so far)");
    }
  }
  view_->forget_before(now - spec_.lease * kForgetAfterLeases);
  if (!changed) return;
  log_transitions(before);
  const cosmic::AdmissionReport was = gateway_.admission();
  gateway_.set_peer_reservations(view_->reservations());
  log_verdict_changes(was, gateway_.admission());
  peers_changed_ = true;
}

void FederationMember::announce() {
  std::set<std::string> violated = gateway_.violated_channel_names();
  if (gateway_.generation() == announced_generation_ && !peers_changed_ && violated == announced_violated_) return;
  cosmic::Announcement now = cosmic::announcement_of(gateway_.identity(), gateway_.knowledge_base(), 0, violated);
  if (claim_) now.claim = claim_->segments;
  if (!announced_ || *announced_ != now) {
    cosmic::Announcement numbered = now;
    numbered.revision = ++revision_;
    if (!link_->publish(numbered.gateway, cosmic::encode(numbered))) {
      log_.log(cosmic::LogLevel::warning, "federation: cannot publish this gateway's announcement; trying again");
      return;  // nothing marked announced: the next tick tries again
    }
    announced_ = std::move(now);
  }
  announced_generation_ = gateway_.generation();
  announced_violated_ = std::move(violated);
  peers_changed_ = false;
}

void FederationMember::tick(cosmic::Nanos now) {
  follow_configuration();
  if (!link_) return;
  hear(now);
  if (claim_ && now >= claim_->deadline) end_claim();
  announce();
}

void FederationMember::end_claim() {
  if (!claim_) return;
  auto commit = std::move(claim_->commit);
  claim_.reset();
  peers_changed_ = true;  // the claim is over: announce without it, committed or not
  commit();               // admits again if what the others reserve or claim changed meanwhile
}

bool FederationMember::touches_shared_network(const cosmic::BindPlan& plan) const {
  const cosmic::Config& config = gateway_.config();
  for (const cosmic::ChannelSpec& channel : plan.channels) {
    for (const auto* names : {&channel.publishers, &channel.subscribers}) {
      for (const std::string& name : *names) {
        const cosmic::SegmentSpec* segment = config.find_segment(name);
        if (segment && view_->shared(cosmic::network_identity(*segment))) return true;
      }
    }
  }
  return false;
}

void FederationMember::gate(const cosmic::BindPlan& plan, std::function<void()> commit) {
  if (!link_ || !view_ || claim_ || !plan.kb || !touches_shared_network(plan)) {
    commit();
    return;
  }
  const auto now = std::chrono::duration_cast<cosmic::Nanos>(std::chrono::steady_clock::now().time_since_epoch());
  std::vector<cosmic::AnnouncedSegment> claimed = cosmic::announcement_of(gateway_.identity(), *plan.kb, 0).segments;
  claim_ = Claim{now + spec_.claim_window, std::move(commit), std::move(claimed)};
  peers_changed_ = true;  // announce() publishes the claim now, not at the next change
  announce();
}

nlohmann::json FederationMember::peers_json(cosmic::Nanos now) const {
  const FederationSnapshot s = snapshot(now);
  nlohmann::json peers = nlohmann::json::array();
  for (const auto& p : s.peers) {
    peers.push_back({{"id", p.id},
                     {"name", p.name},
                     {"state", p.state},
                     {"subject", s.secure ? nlohmann::json(p.subject) : nlohmann::json()},
                     {"last_heard_s", p.last_heard_age_seconds},
                     {"revision", p.revision},
                     {"channels", p.channels}});
  }
  if (view_) {
    std::size_t i = 0;
    for (const auto& [id, peer] : view_->peers()) {
      nlohmann::json segments = nlohmann::json::array();
      for (const auto& seg : peer.announcement.segments) {
        segments.push_back({{"name", seg.name},
                            {"type", cosmic::to_string(seg.type)},
                            {"network", seg.network},
                            {"load", seg.load},
                            {"frames", seg.frames.size()}});
      }
      peers[i++]["segments"] = segments;
    }
  }
  return {{"ok", true},
          {"federation",
           {{"enabled", s.enabled},
            {"segment", s.segment},
            {"secure", s.secure},
            {"lease_s", std::chrono::duration<double>(spec_.lease).count()},
            {"error", start_error_}}},
          {"peers", peers},
          {"counters",
           {{"received", s.view.received},
            {"applied", s.view.applied},
            {"stale", s.view.stale},
            {"refused", s.view.refused},
            {"last_refusal", s.view.last_refusal},
            {"dropped", s.link.dropped},
            {"published", s.link.published},
            {"publish_errors", s.link.publish_errors},
            {"pending_takeovers", view_ ? view_->pending_takeovers() : 0},
            {"frames_over_cap", s.view.frames_over_cap}}}};
}

FederationSnapshot FederationMember::snapshot(cosmic::Nanos now) const {
  FederationSnapshot s;
  s.enabled = link_ != nullptr;
  s.segment = spec_.segment;
  s.secure = segment_.dds.security.has_value();
  if (!view_) return s;
  for (const auto& [id, peer] : view_->peers()) {
    s.peers.push_back({cosmic::gateway_id_text(id), peer.announcement.name, cosmic::to_string(peer.state), peer.subject,
                       seconds_between(peer.last_heard, now), peer.announcement.revision,
                       peer.announcement.channels.size()});
  }
  s.view = view_->counters();
  s.link = link_->counters();
  return s;
}

}  // namespace cosmicd

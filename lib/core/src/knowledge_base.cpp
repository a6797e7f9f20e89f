#include "cosmic/knowledge_base.hpp"

#include <algorithm>

#include "cosmic/can_wire.hpp"

namespace cosmic {

const char* to_string(SegmentHealth value) {
  switch (value) {
    case SegmentHealth::up: return "up";
    case SegmentHealth::degraded: return "degraded";
    case SegmentHealth::down: return "down";
  }
  return "?";
}

KnowledgeBase::KnowledgeBase(GatewaySpec gateway, std::vector<SegmentSpec> segments, std::set<std::uint16_t> reserved_etags)
    : gateway_(std::move(gateway)), reserved_etags_(std::move(reserved_etags)) {
  for (auto& spec : segments) segments_.push_back(SegmentState{std::move(spec), SegmentHealth::up, {}});
  current_ = evaluate(gateway_, segment_specs(), bound_, etags_);
}

std::vector<SegmentSpec> KnowledgeBase::segment_specs() const {
  std::vector<SegmentSpec> specs;
  specs.reserve(segments_.size());
  for (const auto& state : segments_) specs.push_back(state.spec);
  return specs;
}

bool KnowledgeBase::touches_can(const ChannelSpec& channel) const {
  auto is_can = [&](const std::string& name) {
    return std::any_of(segments_.begin(), segments_.end(),
                       [&](const auto& s) { return s.spec.name == name && s.spec.type == SegmentType::can; });
  };
  return std::any_of(channel.publishers.begin(), channel.publishers.end(), is_can) ||
         std::any_of(channel.subscribers.begin(), channel.subscribers.end(), is_can);
}

std::optional<std::uint16_t> KnowledgeBase::allocate_etag(const EtagMap& in_use) const {
  for (std::uint16_t etag = kMaxEtag; etag > kHighestReservedEtag; --etag) {
    if (reserved_etags_.count(etag)) continue;
    const bool taken = std::any_of(in_use.begin(), in_use.end(), [&](const auto& e) { return e.second == etag; });
    if (!taken) return etag;
  }
  return std::nullopt;
}

namespace {
ChannelReport rejection(const ChannelSpec& channel, std::string reason) {
  ChannelReport report;
  report.name = channel.name;
  report.cls = channel.cls;
  report.verdict = Verdict::rejected;
  report.reasons.push_back(std::move(reason));
  return report;
}
}  // namespace

KnowledgeBase::Trial KnowledgeBase::trial(const ChannelSpec& channel) const {
  Trial t;
  t.etags = etags_;
  t.channels = bound_;
  if (find_bound(channel.name)) {
    t.report = rejection(channel, "channel " + channel.name + " is already bound");
    return t;
  }
  for (const auto& other : bound_) {
    if (other.subject == channel.subject) {
      t.report = rejection(channel, "subject already carried by bound channel " + other.name);
      return t;
    }
  }
  if (touches_can(channel)) {
    if (channel.etag) {
      for (const auto& [name, etag] : etags_) {
        if (etag == *channel.etag) {
          t.report = rejection(channel, "etag " + std::to_string(etag) + " is already used by channel " + name);
          return t;
        }
      }
      t.etags[channel.name] = *channel.etag;
    } else if (const auto etag = allocate_etag(etags_)) {
      t.etags[channel.name] = *etag;
    } else {
      t.report = rejection(channel, "no free etag left (101..16383 all in use)");
      return t;
    }
  }
  t.channels.push_back(channel);
  t.evaluation = evaluate(gateway_, segment_specs(), t.channels, t.etags);
  t.report = t.evaluation.channels.back();
  for (std::size_t i = 0; i + 1 < t.channels.size(); ++i) {
    const ChannelReport& existing = t.evaluation.channels[i];
    if (existing.cls != ChannelClass::hrt || existing.verdict != Verdict::rejected) continue;
    t.report.verdict = Verdict::rejected;
    for (const auto& reason : existing.reasons) {
      t.report.reasons.push_back("would break hrt channel " + existing.name + ": " + reason);
    }
  }
  return t;
}

BindOutcome KnowledgeBase::bind(const ChannelSpec& channel) {
  Trial t = trial(channel);
  if (t.report.verdict != Verdict::rejected) {
    bound_ = std::move(t.channels);
    etags_ = std::move(t.etags);
    current_ = std::move(t.evaluation);
  }
  return BindOutcome{std::move(t.report)};
}

ChannelReport KnowledgeBase::probe(const ChannelSpec& channel) const { return trial(channel).report; }

bool KnowledgeBase::unbind(const std::string& name) {
  const auto it = std::find_if(bound_.begin(), bound_.end(), [&](const auto& c) { return c.name == name; });
  if (it == bound_.end()) return false;
  bound_.erase(it);
  etags_.erase(name);
  current_ = evaluate(gateway_, segment_specs(), bound_, etags_);
  return true;
}

void KnowledgeBase::set_health(const std::string& segment, SegmentHealth health, std::string detail) {
  for (auto& state : segments_) {
    if (state.spec.name != segment) continue;
    state.health = health;
    state.health_detail = std::move(detail);
  }
}

AdmissionReport KnowledgeBase::report() const {
  AdmissionReport out;
  out.segments = current_.segments;
  out.channels = current_.channels;
  for (auto& channel : out.channels) {
    for (const auto& hop : channel.hops) {
      const auto state = std::find_if(segments_.begin(), segments_.end(), [&](const auto& s) { return s.spec.name == hop.segment; });
      if (state == segments_.end() || state->health == SegmentHealth::up) continue;
      channel.verdict = std::max(channel.verdict, Verdict::degraded);
      channel.reasons.push_back("segment " + hop.segment + " is " + to_string(state->health) +
                                (state->health_detail.empty() ? "" : ": " + state->health_detail));
    }
  }
  return out;
}

const ChannelSpec* KnowledgeBase::find_bound(const std::string& name) const {
  const auto it = std::find_if(bound_.begin(), bound_.end(), [&](const auto& c) { return c.name == name; });
  return it == bound_.end() ? nullptr : &*it;
}

std::optional<std::uint16_t> KnowledgeBase::etag_of(const std::string& channel) const {
  const auto it = etags_.find(channel);
  if (it == etags_.end()) return std::nullopt;
  return it->second;
}

AdmissionReport admit_all(const Config& config) {
  std::set<std::uint16_t> reserved;
  for (const auto& channel : config.channels) {
    if (channel.etag) reserved.insert(*channel.etag);
  }
  KnowledgeBase kb(config.gateway, config.segments, reserved);
  std::vector<const ChannelSpec*> rejected;
  for (const auto& channel : config.channels) {
    if (!kb.bind(channel).bound()) rejected.push_back(&channel);
  }
  AdmissionReport report = kb.report();
  for (const ChannelSpec* channel : rejected) report.channels.push_back(kb.probe(*channel));
  return report;
}

}  // namespace cosmic

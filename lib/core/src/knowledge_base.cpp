#include "cosmic/knowledge_base.hpp"

#include <algorithm>

#include "cosmic/can_background.hpp"
#include "cosmic/can_wire.hpp"

namespace cosmic {

const char* to_string(SegmentHealth value) {
  switch (value) {
    case SegmentHealth::up:
      return "up";
    case SegmentHealth::degraded:
      return "degraded";
    case SegmentHealth::down:
      return "down";
  }
  return "?";
}

KnowledgeBase::KnowledgeBase(GatewaySpec gateway, std::vector<SegmentSpec> segments,
                             std::set<std::uint16_t> reserved_etags)
    : set_(std::move(gateway), segments), reserved_etags_(std::move(reserved_etags)) {
  for (auto& spec : segments) segments_.push_back(SegmentState{std::move(spec), SegmentHealth::up, {}});
  for (const std::uint16_t etag : reserved_etags_) {
    if (etag <= kMaxEtag) etag_taken_.set(etag);
  }
  for (const SegmentState& segment : segments_) {
    for (const CanBackgroundFrame& frame : segment.spec.can.background) {
      if (frame.extended) etag_taken_.set(frame.can_id & kEtagMask);
    }
  }
}

// A CAN hop in the COSMIC/FAMOUSO layout, which needs an etag (a native one does not).
bool KnowledgeBase::needs_etag(const ChannelSpec& channel) const {
  auto is_can = [&](const std::string& name) {
    return !channel.native_can(name) && std::any_of(segments_.begin(), segments_.end(), [&](const auto& s) {
      return s.spec.name == name && s.spec.type == SegmentType::can;
    });
  };
  return std::any_of(channel.publishers.begin(), channel.publishers.end(), is_can) ||
         std::any_of(channel.subscribers.begin(), channel.subscribers.end(), is_can);
}

// The highest etag neither reserved nor bound.
std::optional<std::uint16_t> KnowledgeBase::allocate_etag() const {
  for (std::uint16_t etag = kMaxEtag; etag > kHighestReservedEtag; --etag) {
    if (!etag_taken_.test(etag) && !peer_etags_.count(etag) && !native_etags_.count(etag)) return etag;
  }
  return std::nullopt;
}

namespace {

std::optional<std::string> static_etag_owner(const EtagMap& etags, std::uint16_t etag) {
  for (const auto& [name, e] : etags) {
    if (e == etag) return name;
  }
  return std::nullopt;
}

std::uint16_t etag_bits(const NativeCanFrame& frame) { return static_cast<std::uint16_t>(frame.can_id & kEtagMask); }
}  // namespace

// A native identity another bound channel holds, or an extended native identifier whose etag bits
// a bound COSMIC channel uses (or the reverse): the reason, or nothing.
Result<void> KnowledgeBase::check_native_identities(const ChannelSpec& channel,
                                                    std::optional<std::uint16_t> etag) const {
  for (const NativeBinding& binding : channel.native) {
    const std::string identity = native_identity(binding);
    if (const auto owner = native_owners_.find({binding.segment, identity}); owner != native_owners_.end()) {
      return Error{identity + " on segment " + binding.segment + " is already carried by bound channel " +
                   owner->second};
    }
    if (!binding.can || !binding.can->extended) continue;
    if (const auto owner = static_etag_owner(etags_, etag_bits(*binding.can))) {
      return Error{"extended identifier " + identity + " reads as etag " + std::to_string(etag_bits(*binding.can)) +
                   " of bound channel " + *owner + " to COSMIC devices"};
    }
  }
  if (const auto owner = etag ? native_etags_.find(*etag) : native_etags_.end(); owner != native_etags_.end()) {
    return Error{"etag " + std::to_string(*etag) + " is the etag bits of bound channel " + owner->second +
                 "'s native extended identifier"};
  }
  return {};
}

KnowledgeBase::Attempt KnowledgeBase::attempt(const ChannelSpec& channel,
                                              std::optional<std::uint16_t> preferred_etag) const {
  Attempt a;
  if (find_bound(channel.name)) {
    a.report = rejected_report(channel, "channel " + channel.name + " is already bound");
    return a;
  }
  if (const auto other = subjects_.find(channel.subject); other != subjects_.end()) {
    a.report = rejected_report(channel, "subject already carried by bound channel " + other->second);
    return a;
  }
  if (needs_etag(channel)) {
    if (channel.etag) {
      if (const auto owner = static_etag_owner(etags_, *channel.etag)) {
        a.report =
            rejected_report(channel, "etag " + std::to_string(*channel.etag) + " is already used by channel " + *owner);
        return a;
      }
      if (const auto peer = peer_etags_.find(*channel.etag); peer != peer_etags_.end()) {
        a.report = rejected_report(channel, "etag " + std::to_string(*channel.etag) +
                                                " is carried by another gateway's frame " + peer->second +
                                                " on a shared CAN bus (cosmicctl peers)");
        return a;
      }
      a.etag = *channel.etag;
    } else if (preferred_etag && *preferred_etag > kHighestReservedEtag && *preferred_etag <= kMaxEtag &&
               !etag_taken_.test(*preferred_etag) && !peer_etags_.count(*preferred_etag) &&
               !native_etags_.count(*preferred_etag)) {
      a.etag = *preferred_etag;
    } else if (const auto etag = allocate_etag()) {
      a.etag = *etag;
    } else {
      a.report = rejected_report(channel, "no free etag left (101..16383 all in use)");
      return a;
    }
  }
  if (const Result<void> distinct = check_native_identities(channel, channel.etag); !distinct) {
    a.report = rejected_report(channel, distinct.error().text);
    return a;
  }
  a.trial = set_.trial(channel, a.etag.value_or(0));
  a.report = a.trial->report;
  add_upstream(channel, a.report);
  for (const AdmissionSet::Trial::BrokenFrame& frame : a.trial->broken_frames) {
    a.report.verdict = Verdict::rejected;
    a.report.reasons.push_back("would break the hrt frame " + frame.name + " of " + frame.origin + ": R = " +
                               (frame.response ? format_duration(*frame.response) : std::string("unbounded")) + " > " +
                               format_duration(frame.deadline) + ", the most its channel there allows");
  }
  for (const ChannelReport& existing : a.trial->broken_hrt) {
    a.report.verdict = Verdict::rejected;
    for (const auto& reason : existing.reasons) {
      a.report.reasons.push_back("would break hrt channel " + existing.name + ": " + reason);
    }
  }
  return a;
}

BindOutcome KnowledgeBase::bind(const ChannelSpec& channel, std::optional<std::uint16_t> preferred_etag) {
  Attempt a = attempt(channel, preferred_etag);
  if (a.report.verdict != Verdict::rejected) {
    if (a.etag) {
      etags_[channel.name] = *a.etag;
      etag_taken_.set(*a.etag);
    }
    subjects_[channel.subject] = channel.name;
    for (const NativeBinding& binding : channel.native) {
      native_owners_[{binding.segment, native_identity(binding)}] = channel.name;
      if (binding.can && binding.can->extended) native_etags_.emplace(etag_bits(*binding.can), channel.name);
    }
    set_.commit(std::move(*a.trial));
  }
  return BindOutcome{std::move(a.report)};
}

ChannelReport KnowledgeBase::probe(const ChannelSpec& channel) const { return attempt(channel).report; }

bool KnowledgeBase::unbind(const std::string& name) {
  const ChannelSpec* spec = set_.find(name);
  if (!spec) return false;
  subjects_.erase(spec->subject);
  for (const NativeBinding& binding : spec->native) native_owners_.erase({binding.segment, native_identity(binding)});
  std::erase_if(native_etags_, [&](const auto& entry) { return entry.second == name; });
  if (const auto etag = etags_.find(name); etag != etags_.end()) {
    if (!reserved_etags_.count(etag->second)) etag_taken_.reset(etag->second);
    etags_.erase(etag);
  }
  set_.remove(name);
  return true;
}

void KnowledgeBase::add_upstream(const ChannelSpec& channel, ChannelReport& report) const {
  if (peers_.empty()) return;
  const UpstreamPath* slowest = nullptr;
  for (const std::string& publisher : channel.publishers) {
    const auto segment =
        std::find_if(segments_.begin(), segments_.end(), [&](const auto& s) { return s.spec.name == publisher; });
    const PeerReservations* peer = segment == segments_.end() ? nullptr : peers_on(segment->spec);
    if (!peer) continue;
    for (const UpstreamPath& path : peer->senders) {
      if (path.subject != channel.subject) continue;
      if (!slowest || !path.age || (slowest->age && *path.age > *slowest->age)) slowest = &path;
    }
  }
  if (!slowest) return;
  apply_upstream(channel, *slowest, report);
  report.gateway = set_.gateway().name;
}

const PeerReservations* KnowledgeBase::peers_on(const SegmentSpec& segment) const {
  const std::string network = network_identity(segment);
  if (network.empty()) return nullptr;
  const auto found = peers_.find(network);
  return found == peers_.end() ? nullptr : &found->second;
}

std::vector<SegmentSpec> KnowledgeBase::analysed_segments() const {
  std::vector<SegmentSpec> specs;
  for (const SegmentState& state : segments_) {
    SegmentSpec spec = state.spec;
    if (const PeerReservations* peer = peers_on(spec)) {
      if (spec.type == SegmentType::can) {
        CanSegmentProperties theirs = spec.can;
        theirs.background = peer->frames;
        spec.peer_load = background_utilization(theirs);
        spec.can.background.insert(spec.can.background.end(), peer->frames.begin(), peer->frames.end());
      } else if (spec.bandwidth.bits_per_second > 0) {
        spec.peer_load = peer->bits_per_second / static_cast<double>(spec.bandwidth.bits_per_second);
      }
    }
    specs.push_back(std::move(spec));
  }
  return specs;
}

void KnowledgeBase::set_peer_reservations(PeerNetworks peers) {
  if (peers == peers_) return;
  peers_ = std::move(peers);
  collect_peer_etags();
  set_ = AdmissionSet::whole(set_.gateway(), analysed_segments(), set_.channels(), etags_);
}

void KnowledgeBase::collect_peer_etags() {
  peer_etags_.clear();
  for (const SegmentState& state : segments_) {
    const PeerReservations* peer = state.spec.type == SegmentType::can ? peers_on(state.spec) : nullptr;
    if (!peer) continue;
    for (const CanBackgroundFrame& frame : peer->frames) {
      if (frame.extended) peer_etags_.emplace(static_cast<std::uint16_t>(frame.can_id & kEtagMask), frame.name);
    }
  }
}

void KnowledgeBase::add_segment(SegmentSpec segment) {
  for (const CanBackgroundFrame& frame : segment.can.background) {
    if (segment.type == SegmentType::can && frame.extended) etag_taken_.set(frame.can_id & kEtagMask);
  }
  segments_.push_back(SegmentState{std::move(segment), SegmentHealth::up, {}});
  collect_peer_etags();
  set_.add_segment(analysed_segments().back());
}

bool KnowledgeBase::remove_segment(const std::string& name) {
  const auto found =
      std::find_if(segments_.begin(), segments_.end(), [&](const SegmentState& s) { return s.spec.name == name; });
  if (found == segments_.end() || !set_.remove_segment(name)) return false;
  segments_.erase(found);
  // Its background frames' etag bits are free again unless reserved, bound or another's.
  etag_taken_.reset();
  for (const std::uint16_t etag : reserved_etags_) {
    if (etag <= kMaxEtag) etag_taken_.set(etag);
  }
  for (const SegmentState& segment : segments_) {
    for (const CanBackgroundFrame& frame : segment.spec.can.background) {
      if (segment.spec.type == SegmentType::can && frame.extended) etag_taken_.set(frame.can_id & kEtagMask);
    }
  }
  for (const auto& [channel, etag] : etags_) etag_taken_.set(etag);
  collect_peer_etags();
  return true;
}

void KnowledgeBase::set_health(const std::string& segment, SegmentHealth health, std::string detail) {
  for (auto& state : segments_) {
    if (state.spec.name != segment) continue;
    state.health = health;
    state.health_detail = std::move(detail);
    return;  // names are unique: the detail is moved once
  }
}

AdmissionReport KnowledgeBase::report() const {
  AdmissionReport out;
  out.segments = set_.loads();
  out.channels = set_.reports();
  for (auto& channel : out.channels) {
    if (const ChannelSpec* spec = set_.find(channel.name)) add_upstream(*spec, channel);
    if (channel.verdict == Verdict::rejected) {  // only with other gateways' reservations
      channel.verdict = Verdict::degraded;
      channel.reasons.push_back("bound before other gateways' reservations on the same networks were known");
    }
    if (const auto etag = etags_.find(channel.name); etag != etags_.end()) {
      if (const auto peer = peer_etags_.find(etag->second); peer != peer_etags_.end()) {
        channel.verdict = std::max(channel.verdict, Verdict::degraded);
        channel.reasons.push_back("etag " + std::to_string(etag->second) +
                                  " is also carried by another gateway's frame " + peer->second +
                                  " on a shared CAN bus: devices bound to one read the other's; give it a static etag");
      }
    }
    for (const auto& hop : channel.hops) {
      const auto state =
          std::find_if(segments_.begin(), segments_.end(), [&](const auto& s) { return s.spec.name == hop.segment; });
      if (state == segments_.end() || state->health == SegmentHealth::up) continue;
      channel.verdict = std::max(channel.verdict, Verdict::degraded);
      channel.reasons.push_back("segment " + hop.segment + " is " + to_string(state->health) +
                                (state->health_detail.empty() ? "" : ": " + state->health_detail));
    }
  }
  return out;
}

const ChannelSpec* KnowledgeBase::find_bound(const std::string& name) const { return set_.find(name); }

std::optional<std::uint16_t> KnowledgeBase::etag_of(const std::string& channel) const {
  const auto it = etags_.find(channel);
  if (it == etags_.end()) return std::nullopt;
  return it->second;
}

std::set<std::uint16_t> reserved_etags(const Config& config) {
  std::set<std::uint16_t> reserved;
  for (const auto& channel : config.channels) {
    if (channel.etag) reserved.insert(*channel.etag);
    for (const NativeBinding& binding : channel.native) {
      if (binding.can && binding.can->extended) reserved.insert(etag_bits(*binding.can));
    }
  }
  return reserved;
}

AdmissionReport admit_all(const Config& config) {
  KnowledgeBase kb(config.gateway, config.segments, reserved_etags(config));
  std::vector<const ChannelSpec*> rejected;
  for (const auto& channel : config.channels) {
    if (!kb.bind(channel).bound()) rejected.push_back(&channel);
  }
  AdmissionReport report = kb.report();
  for (const ChannelSpec* channel : rejected) report.channels.push_back(kb.probe(*channel));
  return report;
}

}  // namespace cosmic

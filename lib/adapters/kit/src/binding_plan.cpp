#include "cosmic/binding_plan.hpp"

#include <algorithm>
#include <set>
#include <utility>

namespace cosmic {

namespace {

bool same_hop(const ChannelBinding& a, const ChannelBinding& b) { return a.id == b.id && a.role == b.role; }

bool same_plan(const ChannelBinding& a, const ChannelBinding& b) {
  if (a.spec != b.spec || a.can.has_value() != b.can.has_value()) return false;
  if (!a.can) return true;
  const CanHopPlan& x = *a.can;
  const CanHopPlan& y = *b.can;
  return x.profile == y.profile && x.native == y.native && x.extended == y.extended && x.priority == y.priority &&
         x.can_id == y.can_id && x.etag == y.etag && x.frame_bytes == y.frame_bytes &&
         x.frames_per_event == y.frames_per_event;
}

}  // namespace

BindingPlan::BindingPlan(std::span<const ChannelBinding> bindings) : bindings_(bindings) {
  std::set<std::pair<ChannelId, HopRole>> seen;
  for (const ChannelBinding& b : bindings_) {
    if (b.id == kNoChannel || b.spec.name.empty()) {
      refuse(b, "the binding has no channel id or name");
    } else if (!seen.emplace(b.id, b.role).second) {
      refuse(b, "bound twice as " + std::string(b.role == HopRole::publisher ? "publisher" : "subscriber"));
    }
  }
}

void BindingPlan::refuse(const ChannelBinding& binding, std::string_view why) {
  // Bindings without an id are refused one by one: kNoChannel names no channel to refuse twice.
  if (binding.id != kNoChannel && refused(binding.id)) return;
  refusals_.push_back(ChannelRefusal{binding.id, std::string(why)});
  refused_names_.push_back(binding.spec.name.empty() ? "(unnamed, id " + std::to_string(binding.id) + ")"
                                                     : binding.spec.name);
}

bool BindingPlan::refused(ChannelId channel) const noexcept {
  return std::any_of(refusals_.begin(), refusals_.end(), [&](const ChannelRefusal& r) { return r.channel == channel; });
}

std::vector<const ChannelBinding*> BindingPlan::accepted() const {
  std::vector<const ChannelBinding*> out;
  out.reserve(bindings_.size());
  for (const ChannelBinding& b : bindings_) {
    if (b.id != kNoChannel && !b.spec.name.empty() && !refused(b.id)) out.push_back(&b);
  }
  return out;
}

std::vector<ChannelBinding> BindingPlan::carried() const {
  std::vector<ChannelBinding> out;
  for (const ChannelBinding* b : accepted()) out.push_back(*b);
  return out;
}

BindingDiff BindingPlan::diff(std::span<const ChannelBinding> carried) const {
  BindingDiff d;
  const std::vector<const ChannelBinding*> wanted = accepted();
  for (const ChannelBinding* b : wanted) {
    const auto before =
        std::find_if(carried.begin(), carried.end(), [&](const ChannelBinding& c) { return same_hop(c, *b); });
    if (before == carried.end()) {
      d.added.push_back(b);
    } else if (!same_plan(*before, *b)) {
      d.changed.push_back(b);
    }
  }
  for (const ChannelBinding& c : carried) {
    const bool kept =
        std::any_of(wanted.begin(), wanted.end(), [&](const ChannelBinding* b) { return same_hop(c, *b); });
    if (!kept) d.removed.push_back(c);
  }
  return d;
}

Status BindingPlan::status() const {
  Status status;
  for (std::size_t i = 0; i < refusals_.size(); ++i) {
    status.ok = false;
    status.error += (status.error.empty() ? "" : "; ") + ("channel " + refused_names_[i] + ": " + refusals_[i].reason);
  }
  status.refused = refusals_;
  return status;
}

Status not_started(std::string_view segment) {
  return Status::failure("segment " + std::string(segment) + " is not started");
}

}  // namespace cosmic

#include "cosmic/binding_plan.hpp"

#include <map>
#include <set>
#include <utility>

namespace cosmic {

namespace {

using Hop = std::pair<ChannelId, HopRole>;

}  // namespace

BindingPlan::BindingPlan(std::span<const ChannelBinding> bindings) : bindings_(bindings) {
  std::set<Hop> seen;
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
  if (binding.id != kNoChannel && !refused_ids_.insert(binding.id).second) return;
  refusals_.push_back(ChannelRefusal{binding.id, std::string(why)});
  refused_names_.push_back(binding.spec.name.empty() ? "(unnamed, id " + std::to_string(binding.id) + ")"
                                                     : binding.spec.name);
}

bool BindingPlan::refused(ChannelId channel) const noexcept { return refused_ids_.count(channel) > 0; }

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
  std::map<Hop, const ChannelBinding*> before;
  for (const ChannelBinding& c : carried) before.emplace(Hop{c.id, c.role}, &c);
  for (const ChannelBinding* b : accepted()) {
    const auto found = before.find(Hop{b->id, b->role});
    if (found == before.end()) {
      d.added.push_back(b);
      continue;
    }
    if (!(*found->second == *b)) d.changed.push_back(b);
    before.erase(found);  // what is left was carried and is not any more
  }
  for (const ChannelBinding& c : carried) {
    if (before.count(Hop{c.id, c.role})) d.removed.push_back(c);
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

// The plan every adapter's configure() makes before it applies anything: the checks all
// transports share, one refusal per channel, the joined reasons and what changed against the
// bindings the segment carried before. SegmentAdapter::configure states the contract this serves.
//
//  - A binding without a channel id or name is refused; so is a channel bound twice in one role.
//  - A transport adds its own refusals with refuse() while it builds its tables.
//  - A channel is refused at most once, with its first reason, and then in both roles: accepted()
//    never yields a binding of a refused channel.
//  - status() names each refused channel once, in the order refused, and joins the reasons as
//    "channel NAME: why; channel NAME: why".
//
// Threads: a value made and used by the control thread that calls configure(); no locks. It
// refers to the bindings it was made from, which must outlive it.
#pragma once

#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/segment_adapter.hpp"

namespace cosmic {

// What configure() changes against what the segment carried before, by (channel, role).
struct BindingDiff {
  std::vector<const ChannelBinding*> added;    // not carried before in this role
  std::vector<const ChannelBinding*> changed;  // carried before in this role with another spec or plan
  std::vector<ChannelBinding> removed;         // carried before, not any more (refused included)
  bool empty() const noexcept { return added.empty() && changed.empty() && removed.empty(); }
};

class BindingPlan {
 public:
  // Runs the shared checks over `bindings`.
  explicit BindingPlan(std::span<const ChannelBinding> bindings);

  // Refuses `binding`'s channel in every role; a channel already refused keeps its first reason.
  void refuse(const ChannelBinding& binding, std::string_view why);
  bool refused(ChannelId channel) const noexcept;
  bool any_refused() const noexcept { return !refusals_.empty(); }

  // The bindings not refused, in the order given.
  std::vector<const ChannelBinding*> accepted() const;
  // accepted() against `carried` (the accepted bindings of the previous configure()).
  BindingDiff diff(std::span<const ChannelBinding> carried) const;
  // The accepted bindings as values: what the segment carries once the plan is applied.
  std::vector<ChannelBinding> carried() const;

  // ok, or the refused channels with their reasons (never a failure of the whole segment).
  Status status() const;

 private:
  std::span<const ChannelBinding> bindings_;
  std::vector<ChannelRefusal> refusals_;
  std::set<ChannelId> refused_ids_;         // the channels of refusals_, for refused()
  std::vector<std::string> refused_names_;  // parallel to refusals_, for the joined text
};

// The answer of configure() on a segment that is not running (before start(), after stop(), or
// after a start() that failed): a failure of the whole segment, carrying nothing.
Status not_started(std::string_view segment);

}  // namespace cosmic

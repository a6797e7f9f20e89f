// End-to-end across gateways (federation, docs/federation.md): a channel whose events another
// gateway sends onto a network this gateway receives the channel from has a path that starts
// there. Its admission here checks the whole path (the age the events arrive with plus this
// gateway's part) against the channel's reaction_time and temp_validity, and compares the two
// gateways' definitions of the subject. Pure functions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/admission.hpp"
#include "cosmic/model.hpp"

namespace cosmic {

// A channel another gateway sends onto a network, as its announcement describes it.
struct UpstreamPath {
  std::string gateway;  // that gateway's name
  std::string channel;  // its name for the channel there
  std::uint64_t subject = 0;
  ChannelClass cls = ChannelClass::nrt;
  std::optional<Nanos> period;
  std::optional<Nanos> reaction_time;
  std::optional<Nanos> temp_validity;
  std::uint64_t payload = 0;
  std::vector<PathHop> hops;  // every hop before the shared network, on that gateway and before it
  std::optional<Nanos> age;   // worst-case age of its events when sent onto the network; nullopt: unbounded
  bool violated = false;      // that gateway reports the channel `violated` at run time now
  friend bool operator==(const UpstreamPath&, const UpstreamPath&) = default;
};

// Adds `upstream` to the report of `channel` (judged on this gateway alone): its hops before this
// gateway's, the whole path's latency against reaction_time and temp_validity, and a reason for
// every way the upstream gateway's definition differs from this one. An upstream that sends events
// more often or larger than `channel` admits fails the channel like a check does (rejected for
// HRT); other differences (class, reaction_time, temp_validity) degrade it. An upstream that
// reports the channel violated at run time fails it like a missed end-to-end bound.
void apply_upstream(const ChannelSpec& channel, const UpstreamPath& upstream, ChannelReport& report);

}  // namespace cosmic

// Segments added to and removed from the running gateway (Gateway::add_segment, remove_segment):
// a run-time replay's segment (cosmicctl replay). Control thread only.
#include <algorithm>

#include "cosmic/gateway.hpp"

namespace cosmic {

Result<void> Gateway::add_segment(const SegmentSpec& segment) {
  if (!router_) return Error{"the gateway is not running"};
  if (slots_.count(segment.name) || config_.find_segment(segment.name))
    return Error{"a segment named '" + segment.name + "' is running"};
  const std::size_t index = free_slot();
  if (index >= kMaxSegments) return Error{"the gateway runs " + std::to_string(kMaxSegments) + " segments, its most"};
  SegmentSlot slot{index, segment, factory_(segment, identity_, log_), {}};
  if (!slot.adapter) return Error{"cannot create the adapter of segment " + segment.name};
  router_->set_segment(slot.index, segment.name, slot.adapter.get(), egress_lane_floor(segment));
  const Status started = slot.adapter->start(router_->inbox(slot.index));
  if (!started.ok) log_.log(LogLevel::error, "segment " + segment.name + " did not start: " + started.error);
  slots_.emplace(segment.name, std::move(slot));
  config_.segments.push_back(segment);
  // Known to admission from now on; nothing bound is analysed again (CAN priorities and etags stay).
  kb_->add_segment(segment);
  ++generation_;
  log_.log(LogLevel::notice, "segment " + segment.name + " added (" + to_string(segment.type) + ")");
  return {};
}

Result<void> Gateway::remove_segment(const std::string& name) {
  const auto slot = slots_.find(name);
  if (slot == slots_.end()) return Error{"no segment named '" + name + "'"};
  for (const ChannelSpec& channel : kb_->bound_channels()) {
    const auto on = [&](const std::vector<std::string>& names) {
      return std::find(names.begin(), names.end(), name) != names.end();
    };
    if (on(channel.publishers) || on(channel.subscribers))
      return Error{"channel " + channel.name + " still has a hop on segment " + name};
  }
  if (!kb_->remove_segment(name)) return Error{"admission still counts a hop on segment " + name};
  router_->set_segment(slot->second.index, "", nullptr);
  slot->second.adapter->stop();
  slots_.erase(slot);
  std::erase_if(config_.segments, [&](const SegmentSpec& s) { return s.name == name; });
  ++generation_;
  log_.log(LogLevel::notice, "segment " + name + " removed");
  return {};
}

}  // namespace cosmic

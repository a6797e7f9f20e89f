// Segments added to and removed from an admitted set (AdmissionSet::add_segment, remove_segment):
// a run-time replay's segment. Neither touches the analysis of what is bound.
#include <algorithm>

#include "cosmic/admission.hpp"

namespace cosmic {

void AdmissionSet::add_segment(SegmentSpec segment) {
  segment_specs_.push_back(std::move(segment));
  segments_.emplace_back();
  init_segment(segments_.size() - 1);
}

bool AdmissionSet::remove_segment(const std::string& name) {
  const auto found =
      std::find_if(segment_specs_.begin(), segment_specs_.end(), [&](const SegmentSpec& s) { return s.name == name; });
  if (found == segment_specs_.end()) return false;
  const auto gone = static_cast<std::size_t>(found - segment_specs_.begin());
  if (!segments_[gone].hops.empty()) return false;
  segment_specs_.erase(found);
  segments_.erase(segments_.begin() + static_cast<std::ptrdiff_t>(gone));
  // The hops of the segments after it move down one place.
  for (ChannelData& data : data_) {
    for (HopPlace& place : data.places) {
      if (place.segment > gone) --place.segment;
    }
  }
  return true;
}

}  // namespace cosmic

#include "cosmic/model.hpp"

#include <algorithm>

namespace cosmic {

const char* to_string(ChannelClass value) {
  switch (value) {
    case ChannelClass::hrt: return "hrt";
    case ChannelClass::srt: return "srt";
    case ChannelClass::nrt: return "nrt";
  }
  return "?";
}

const char* to_string(SegmentType value) {
  switch (value) {
    case SegmentType::can: return "can";
    case SegmentType::dds: return "dds";
    case SegmentType::lcm: return "lcm";
  }
  return "?";
}

const char* to_string(Reliability value) {
  return value == Reliability::reliable ? "reliable" : "best_effort";
}

const SegmentSpec* Config::find_segment(const std::string& name) const {
  const auto it = std::find_if(segments.begin(), segments.end(), [&](const auto& s) { return s.name == name; });
  return it == segments.end() ? nullptr : &*it;
}

const ChannelSpec* Config::find_channel(const std::string& name) const {
  const auto it = std::find_if(channels.begin(), channels.end(), [&](const auto& c) { return c.name == name; });
  return it == channels.end() ? nullptr : &*it;
}

}  // namespace cosmic

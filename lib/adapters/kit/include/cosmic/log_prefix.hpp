// How every adapter names its segment at the start of a log line or an error text, so that one
// grep finds all a segment said: "CAN segment body-can: ", "DDS segment lan: ", "LCM segment viz: ".
#pragma once

#include <string>
#include <string_view>

#include "cosmic/model.hpp"

namespace cosmic {

inline std::string segment_log_prefix(SegmentType type, std::string_view segment) {
  const char* kind = type == SegmentType::can ? "CAN" : type == SegmentType::dds ? "DDS" : "LCM";
  std::string out = kind;
  out += " segment ";
  out += segment;
  out += ": ";
  return out;
}

}  // namespace cosmic

#include "cosmic/model.hpp"

#include <fnmatch.h>

#include <algorithm>

#include "cosmic/can_background.hpp"

namespace cosmic {

const char* to_string(ChannelClass value) {
  switch (value) {
    case ChannelClass::hrt:
      return "hrt";
    case ChannelClass::srt:
      return "srt";
    case ChannelClass::nrt:
      return "nrt";
  }
  return "?";
}

const char* to_string(SegmentType value) {
  switch (value) {
    case SegmentType::can:
      return "can";
    case SegmentType::dds:
      return "dds";
    case SegmentType::lcm:
      return "lcm";
    case SegmentType::replay:
      return "replay";
  }
  return "?";
}

const char* to_string(Reliability value) { return value == Reliability::reliable ? "reliable" : "best_effort"; }

const char* to_string(DdsRepresentation value) { return value == DdsRepresentation::xcdr2 ? "xcdr2" : "xcdr1"; }

const char* to_string(NativeForm value) {
  switch (value) {
    case NativeForm::source:
      return "source";
    case NativeForm::compact:
      return "compact";
    case NativeForm::json:
      return "json";
  }
  return "?";
}

std::string native_identity(const NativeBinding& binding) {
  if (binding.can) return can_id_text(binding.can->can_id, binding.can->extended);
  if (binding.dds) return binding.dds->topic;
  return binding.lcm_channel.value_or("");
}

std::uint64_t ChannelSpec::payload_on(const std::string& segment) const {
  const HopPayload* hop = hop_on(segment);
  return hop != nullptr && hop->unfit.empty() ? hop->bytes : payload;
}

const HopPayload* ChannelSpec::hop_on(const std::string& segment) const {
  const auto it =
      std::find_if(hop_payloads.begin(), hop_payloads.end(), [&](const HopPayload& h) { return h.segment == segment; });
  return it == hop_payloads.end() ? nullptr : &*it;
}

const NativeBinding* ChannelSpec::native_on(const std::string& segment) const {
  const auto it = std::find_if(native.begin(), native.end(), [&](const auto& n) { return n.segment == segment; });
  return it == native.end() ? nullptr : &*it;
}

const SecocSpec* ChannelSpec::secoc_on(const std::string& segment) const {
  const auto it = std::find_if(secoc.begin(), secoc.end(), [&](const SecocSpec& s) { return s.segment == segment; });
  return it == secoc.end() ? nullptr : &*it;
}

std::optional<NativeCanFrame> ChannelSpec::native_can(const std::string& segment) const {
  const NativeBinding* binding = native_on(segment);
  return binding ? binding->can : std::nullopt;
}

std::optional<NativeDdsTopic> ChannelSpec::native_dds(const std::string& segment) const {
  const NativeBinding* binding = native_on(segment);
  return binding ? binding->dds : std::nullopt;
}

const SegmentSpec* Config::find_segment(const std::string& name) const {
  const auto it = std::find_if(segments.begin(), segments.end(), [&](const auto& s) { return s.name == name; });
  return it == segments.end() ? nullptr : &*it;
}

const ChannelSpec* Config::find_channel(const std::string& name) const {
  const auto it = std::find_if(channels.begin(), channels.end(), [&](const auto& c) { return c.name == name; });
  return it == channels.end() ? nullptr : &*it;
}

const ReplayStream* ReplaySegmentProperties::stream(const std::string& channel) const {
  const auto it =
      std::find_if(streams.begin(), streams.end(), [&](const ReplayStream& s) { return s.channel == channel; });
  return it == streams.end() ? nullptr : &*it;
}

namespace {
// Empty: every name; else a name some fnmatch(3) pattern of `patterns` matches.
bool any_matches(const std::vector<std::string>& patterns, const std::string& name) {
  if (patterns.empty()) return true;
  return std::any_of(patterns.begin(), patterns.end(),
                     [&](const std::string& pattern) { return ::fnmatch(pattern.c_str(), name.c_str(), 0) == 0; });
}
}  // namespace

bool RecordingSpec::selects(const std::string& name) const { return any_matches(channels, name); }

bool ReplaySegmentProperties::selects(const std::string& channel) const { return any_matches(channels, channel); }

}  // namespace cosmic

namespace cosmic {
namespace {

std::vector<std::string> channels_of(const std::vector<FmuVariableMapping>& mappings) {
  std::vector<std::string> out;
  for (const auto& m : mappings)
    if (std::find(out.begin(), out.end(), m.channel) == out.end()) out.push_back(m.channel);
  return out;
}

}  // namespace

std::vector<std::string> FmuSpec::publishes() const { return channels_of(outputs); }
std::vector<std::string> FmuSpec::subscribes() const { return channels_of(inputs); }

std::string client_segment(const SegmentSpec& s, unsigned can_node) {
  switch (s.type) {
    case SegmentType::dds:
      return "dds:" + std::to_string(s.dds.domain) +
             (s.reliability == Reliability::best_effort ? "?reliability=best_effort" : "");
    case SegmentType::lcm:
      return "lcm:" + s.lcm.url;
    case SegmentType::can:
      return "can:" + s.can.interface + "?node=" + std::to_string(can_node);
    case SegmentType::replay:
      break;
  }
  return "";
}

}  // namespace cosmic

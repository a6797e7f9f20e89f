// How a channel is named on a DDS segment: its topic and type, for the envelope and for native
// topics (issue 19). Pure functions: the configuration loader, admission's report and the DDS
// adapter all name a DDS hop through these, so they can never disagree.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>
#include <string_view>

#include "cosmic/model.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// The type of every envelope topic (lib/adapters/dds/idl/Envelope.idl).
inline constexpr const char* kEnvelopeTypeName = "cosmic::Envelope";
// Topic names starting with this are the envelope channels'; a native topic may not use it.
inline constexpr std::string_view kEnvelopeTopicPrefix = "cosmic/";
// The topic on which gateways announce themselves to each other (docs/federation.md), on the
// federation's segment.
inline constexpr const char* kFederationTopicName = "cosmic/federation";
// Longest native topic or type name accepted (Fast DDS and Cyclone both take far longer names;
// this bounds what a configuration can make the gateway announce in discovery).
inline constexpr std::size_t kMaxDdsNameLength = 255;

// "cosmic/<channel name>" with every character a DDS topic name cannot hold ('-', '.') mapped
// to '_' (docs/dds-mapping.md).
std::string dds_topic_name(std::string_view channel_name);

struct DdsTopicRef {
  std::string topic;
  std::string type;
  bool native = false;  // the serialized payload of `type` as is; otherwise a cosmic::Envelope
  DdsRepresentation representation = DdsRepresentation::xcdr1;  // what a writer announces
  friend bool operator==(const DdsTopicRef&, const DdsTopicRef&) = default;
};

// The topic and type of `channel` on the DDS segment `segment`: its native topic there, or the
// envelope topic.
DdsTopicRef dds_topic_of(const ChannelSpec& channel, const std::string& segment);

// Whether the distinct channels among `channels` can share the DDS segment `segment`; the error
// names two that map to one topic.
Result<void> check_dds_topics_distinct(std::span<const ChannelSpec* const> channels, const std::string& segment);
// Every channel among `channels` whose topic on `segment` an earlier, distinct channel already
// maps to, with the reason (the first of them is what check_dds_topics_distinct() says).
std::vector<std::pair<const ChannelSpec*, std::string>> dds_topic_collisions(
    std::span<const ChannelSpec* const> channels, const std::string& segment);

// Whether `name` can be a native topic name (the error says why not). Topic names are letters, digits, '_' and
// '/' separators (ROS 2: rt/<name>, possibly namespaced), start with a letter, at most
// kMaxDdsNameLength characters, and not under kEnvelopeTopicPrefix.
Result<void> check_dds_topic_name(std::string_view name);
// Whether `name` can be a type name (the error says why not): IDL identifiers (letters, digits, '_', starting
// with a letter or '_') joined by "::", at most kMaxDdsNameLength characters.
Result<void> check_dds_type_name(std::string_view name);

}  // namespace cosmic

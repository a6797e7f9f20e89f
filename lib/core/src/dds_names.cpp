#include "cosmic/dds_names.hpp"

#include "cosmic/escaped_text.hpp"

#include <cstdio>
#include <map>

namespace cosmic {
namespace {

bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool printable(char c) { return c > ' ' && c < 0x7f; }

// A name as error messages show it, quoted, at most 40 characters (escaped_text.hpp).
std::string quoted(std::string_view text) { return "'" + escaped_text(text, 40) + "'"; }

// One character, as text: 'c' when printable, 0xNN otherwise.
std::string character_text(char c) {
  if (printable(c)) return std::string("'") + c + "'";
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
  return text;
}

std::optional<std::string> length_problem(const char* what, std::string_view name) {
  if (name.empty()) return std::string("empty ") + what + " name";
  if (name.size() <= kMaxDdsNameLength) return std::nullopt;
  return std::string(what) + " name " + quoted(name) + " has " + std::to_string(name.size()) + " characters, at most " +
         std::to_string(kMaxDdsNameLength) + " are accepted";
}

}  // namespace

std::string dds_topic_name(std::string_view channel_name) {
  std::string name(kEnvelopeTopicPrefix);
  for (const char c : channel_name) {
    // Channel names allow [A-Za-z0-9_.-]; a DDS topic name only letters, digits, '_' and the
    // '/' separator (Cyclone DDS refuses the rest).
    name.push_back(is_letter(c) || is_digit(c) || c == '_' ? c : '_');
  }
  return name;
}

DdsTopicRef dds_topic_of(const ChannelSpec& channel, const std::string& segment) {
  if (const std::optional<NativeDdsTopic> native = channel.native_dds(segment)) {
    return DdsTopicRef{native->topic, native->type, true, native->representation};
  }
  return DdsTopicRef{dds_topic_name(channel.name), kEnvelopeTypeName, false, DdsRepresentation::xcdr1};
}

std::vector<std::pair<const ChannelSpec*, std::string>> dds_topic_collisions(
    std::span<const ChannelSpec* const> channels, const std::string& segment) {
  std::vector<std::pair<const ChannelSpec*, std::string>> collisions;
  std::map<std::string, std::string_view> owner;  // topic -> channel name
  for (const ChannelSpec* channel : channels) {
    const DdsTopicRef ref = dds_topic_of(*channel, segment);
    const auto [it, inserted] = owner.emplace(ref.topic, channel->name);
    if (!inserted && it->second != channel->name) {
      collisions.emplace_back(channel, "channels '" + std::string(it->second) + "' and '" + channel->name +
                                           "' both map to DDS topic " + it->first +
                                           (ref.native ? "" : " ('-' and '.' become '_')") + "; rename one of them");
    }
  }
  return collisions;
}

Result<void> check_dds_topics_distinct(std::span<const ChannelSpec* const> channels, const std::string& segment) {
  auto collisions = dds_topic_collisions(channels, segment);
  if (collisions.empty()) return {};
  return Error{std::move(collisions.front().second)};
}

Result<void> check_dds_topic_name(std::string_view name) {
  if (auto problem = length_problem("topic", name)) return Error{*problem};
  if (!is_letter(name.front())) return Error{"topic name " + quoted(name) + " does not start with a letter"};
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '/' && (i + 1 == name.size() || name[i + 1] == '/')) {
      return Error{"topic name " + quoted(name) + " has an empty part between '/' separators"};
    }
    if (!is_letter(c) && !is_digit(c) && c != '_' && c != '/') {
      return Error{"topic name " + quoted(name) + " has " + character_text(c) + " at position " +
                   std::to_string(i + 1) + "; only letters, digits, '_' and '/' are accepted"};
    }
  }
  if (name.substr(0, kEnvelopeTopicPrefix.size()) == kEnvelopeTopicPrefix) {
    return Error{"topic name " + quoted(name) + " is under " + std::string(kEnvelopeTopicPrefix) +
                 ", which the gateway's envelope channels use"};
  }
  return {};
}

Result<void> check_dds_type_name(std::string_view name) {
  if (auto problem = length_problem("type", name)) return Error{*problem};
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = name.find("::", start);
    const std::string_view part =
        name.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
    if (part.empty() || !(is_letter(part.front()) || part.front() == '_')) {
      return Error{"type name " + quoted(name) +
                   " has a part that is not an IDL identifier (parts are joined by '::')"};
    }
    for (const char c : part) {
      if (!is_letter(c) && !is_digit(c) && c != '_') {
        return Error{"type name " + quoted(name) + " has " + character_text(c) +
                     "; only IDL identifiers (letters, digits, '_') joined by '::' are accepted"};
      }
    }
    if (end == std::string_view::npos) return {};
    start = end + 2;
  }
}

}  // namespace cosmic

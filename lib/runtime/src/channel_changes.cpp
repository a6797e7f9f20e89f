#include "cosmic/channel_changes.hpp"

#include <cstdio>

#include "cosmic/units.hpp"

namespace cosmic {
namespace {

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return "[" + out + "]";
}

std::string duration(const std::optional<Nanos>& value) { return value ? format_duration(*value) : std::string("-"); }

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(value));
  return text;
}

std::string natives(const std::vector<NativeBinding>& bindings) {
  std::string out;
  for (const auto& b : bindings) out += (out.empty() ? "" : ", ") + b.segment + ": " + native_identity(b);
  return "{" + out + "}";
}

}  // namespace

std::vector<std::string> definition_changes(const ChannelSpec& before, const ChannelSpec& after) {
  std::vector<std::string> changes;
  auto note = [&changes](const char* field, const std::string& was, const std::string& now) {
    if (was != now) changes.push_back(std::string(field) + ": " + was + " -> " + now);
  };
  note("subject", hex(before.subject), hex(after.subject));
  note("class", to_string(before.cls), to_string(after.cls));
  note("period", duration(before.period), duration(after.period));
  note("reaction_time", duration(before.reaction_time), duration(after.reaction_time));
  note("omission_degree", std::to_string(before.omission_degree), std::to_string(after.omission_degree));
  note("temp_validity", duration(before.temp_validity), duration(after.temp_validity));
  note("payload", std::to_string(before.payload) + " B", std::to_string(after.payload) + " B");
  note("etag", before.etag ? std::to_string(*before.etag) : "assigned",
       after.etag ? std::to_string(*after.etag) : "assigned");
  note("lcm_encoding", before.lcm_encoding == LcmEncoding::raw ? "raw" : "envelope",
       after.lcm_encoding == LcmEncoding::raw ? "raw" : "envelope");
  note("publishers", list(before.publishers), list(after.publishers));
  note("subscribers", list(before.subscribers), list(after.subscribers));
  note("native", natives(before.native), natives(after.native));
  return changes;
}

}  // namespace cosmic

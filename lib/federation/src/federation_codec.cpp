// The announcement as JSON (docs/federation.md, "Announcement"). Decoding treats the text as
// hostile: nesting is checked before parsing, every field is type- and range-checked, and the
// first problem found is the answer.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cosmic/federation.hpp"
#include "cosmic/json_nesting.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::json;

// Deepest nesting of a valid announcement: object > segments > segment > frames > frame.
constexpr int kMaxNesting = 6;
// Longest period or latency an announcement may state (a day): beyond it a number is a mistake.
constexpr std::int64_t kMaxAnnouncedNanos = kMaxAnnouncedDuration.count();

// 1 -> "1", 1e12 -> "1e+12": a bound as a refusal quotes it.
std::string format_number(double value) { return Json(value).dump(); }

const char* role_text(HopRole role) { return role == HopRole::publisher ? "publisher" : "subscriber"; }

Json nanos_or_null(const std::optional<Nanos>& value) { return value ? Json(value->count()) : Json(nullptr); }

Json frame_json(const AnnouncedFrame& f) {
  return {{"channel", f.channel},
          {"can_id", f.can_id},
          {"extended", f.extended},
          {"length", f.length},
          {"period_ns", f.period.count()},
          {"jitter_ns", f.jitter.count()},
          {"deadline_ns", nanos_or_null(f.deadline)}};
}

Json segment_json(const AnnouncedSegment& s) {
  Json frames = Json::array();
  for (const auto& f : s.frames) frames.push_back(frame_json(f));
  return {{"name", s.name},       {"type", to_string(s.type)},
          {"network", s.network}, {"max_utilization", s.max_utilization},
          {"load", s.load},       {"reserved_bps", s.reserved_bps},
          {"frames", frames}};
}

Json channel_json(const AnnouncedChannel& c) {
  Json hops = Json::array();
  for (const auto& h : c.hops)
    hops.push_back({{"segment", h.segment}, {"role", role_text(h.role)}, {"latency_ns", nanos_or_null(h.latency)}});
  Json upstream = Json::array();
  for (const auto& h : c.upstream) {
    upstream.push_back({{"gateway", h.gateway},
                        {"gateway_id", gateway_id_text(h.gateway_id)},
                        {"segment", h.segment},
                        {"role", role_text(h.role)},
                        {"latency_ns", nanos_or_null(h.latency)}});
  }
  return {{"name", c.name},
          {"subject", c.subject},
          {"class", to_string(c.cls)},
          {"verdict", to_string(c.verdict)},
          {"hops", hops},
          {"end_to_end_ns", nanos_or_null(c.end_to_end)},
          {"period_ns", nanos_or_null(c.period)},
          {"reaction_time_ns", nanos_or_null(c.reaction_time)},
          {"temp_validity_ns", nanos_or_null(c.temp_validity)},
          {"payload", c.payload},
          {"upstream", upstream},
          {"upstream_ns", nanos_or_null(c.upstream_age)},
          {"violated", c.violated}};
}

// Reads one announcement; the first problem throws Refusal (caught by decode_announcement only).
struct Refusal {
  std::string why;
};

class Reader {
 public:
  const Json& field(const Json& object, const char* key, const std::string& where) const {
    if (!object.is_object()) throw Refusal{where + " is not an object"};
    const auto it = object.find(key);
    if (it == object.end()) throw Refusal{where + "." + key + " is missing"};
    return *it;
  }
  std::string text(const Json& object, const char* key, const std::string& where, bool may_be_empty) const {
    const Json& v = field(object, key, where);
    if (!v.is_string()) throw Refusal{where + "." + key + " is not a string"};
    const auto& s = v.get_ref<const std::string&>();
    if (s.size() > kMaxAnnouncedName)
      throw Refusal{where + "." + key + " is longer than " + std::to_string(kMaxAnnouncedName) + " characters"};
    if (s.empty() && !may_be_empty) throw Refusal{where + "." + key + " is empty"};
    for (const char c : s) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        throw Refusal{where + "." + key + " holds a control character"};
    }
    return s;
  }
  std::uint64_t whole(const Json& object, const char* key, const std::string& where, std::uint64_t max) const {
    const Json& v = field(object, key, where);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0)) {
      throw Refusal{where + "." + key + " is not a whole number >= 0"};
    }
    const auto n = v.get<std::uint64_t>();
    if (n > max) throw Refusal{where + "." + key + " = " + std::to_string(n) + " is above " + std::to_string(max)};
    return n;
  }
  Nanos nanos(const Json& object, const char* key, const std::string& where) const {
    return Nanos(static_cast<std::int64_t>(whole(object, key, where, kMaxAnnouncedNanos)));
  }
  std::optional<Nanos> nanos_or_unbounded(const Json& object, const char* key, const std::string& where) const {
    if (field(object, key, where).is_null()) return std::nullopt;
    return nanos(object, key, where);
  }
  double number(const Json& object, const char* key, const std::string& where, double max) const {
    const Json& v = field(object, key, where);
    if (!v.is_number()) throw Refusal{where + "." + key + " is not a number"};
    const double d = v.get<double>();
    if (!std::isfinite(d) || d < 0 || d > max)
      throw Refusal{where + "." + key + " is outside 0.." + format_number(max)};
    return d;
  }
  double ratio(const Json& object, const char* key, const std::string& where) const {
    return number(object, key, where, 1);
  }
  bool flag(const Json& object, const char* key, const std::string& where) const {
    const Json& v = field(object, key, where);
    if (!v.is_boolean()) throw Refusal{where + "." + key + " is not true or false"};
    return v.get<bool>();
  }
  const Json& list(const Json& object, const char* key, const std::string& where, std::size_t max) const {
    const Json& v = field(object, key, where);
    if (!v.is_array()) throw Refusal{where + "." + key + " is not a list"};
    if (v.size() > max)
      throw Refusal{where + "." + key + " has " + std::to_string(v.size()) + " entries, more than " +
                    std::to_string(max)};
    return v;
  }
  template <typename Enum>
  Enum choice(const Json& object, const char* key, const std::string& where,
              std::initializer_list<std::pair<const char*, Enum>> values) const {
    const std::string s = text(object, key, where, false);
    for (const auto& [name, value] : values) {
      if (s == name) return value;
    }
    throw Refusal{where + "." + key + " '" + s + "' is not a known value"};
  }
};

AnnouncedFrame read_frame(const Reader& r, const Json& j, const std::string& where) {
  AnnouncedFrame f;
  f.channel = r.text(j, "channel", where, false);
  f.extended = r.flag(j, "extended", where);
  f.can_id = static_cast<std::uint32_t>(r.whole(j, "can_id", where, f.extended ? 0x1FFFFFFFu : 0x7FFu));
  f.length = static_cast<std::uint32_t>(r.whole(j, "length", where, 64));
  f.period = r.nanos(j, "period_ns", where);
  if (f.period < Nanos(1000)) throw Refusal{where + ".period_ns is below 1 us"};
  f.jitter = r.nanos(j, "jitter_ns", where);
  // A release jitter beyond a second is no CAN frame's: it would only make every analysis diverge.
  if (f.jitter > Nanos(1'000'000'000)) throw Refusal{where + ".jitter_ns is above 1 s"};
  f.deadline = r.nanos_or_unbounded(j, "deadline_ns", where);
  return f;
}

AnnouncedSegment read_segment(const Reader& r, const Json& j, const std::string& where) {
  AnnouncedSegment s;
  s.name = r.text(j, "name", where, false);
  s.type = r.choice<SegmentType>(j, "type", where,
                                 {{"can", SegmentType::can}, {"dds", SegmentType::dds}, {"lcm", SegmentType::lcm}});
  s.network = r.text(j, "network", where, true);
  s.max_utilization = r.ratio(j, "max_utilization", where);
  s.load = r.ratio(j, "load", where);
  s.reserved_bps = r.number(j, "reserved_bps", where, kMaxAnnouncedBitsPerSecond);
  const Json& frames = r.list(j, "frames", where, kMaxAnnouncedFrames);
  if (s.type != SegmentType::can && !frames.empty())
    throw Refusal{where + ".frames is not empty on a " + to_string(s.type) + " segment"};
  for (std::size_t i = 0; i < frames.size(); ++i)
    s.frames.push_back(read_frame(r, frames[i], where + ".frames[" + std::to_string(i) + "]"));
  return s;
}

// A gateway id: 16 lower-case hexadecimal digits, not 0.
std::uint64_t read_id(const Reader& r, const Json& j, const char* key, const std::string& where) {
  const std::string text = r.text(j, key, where, false);
  const std::string at = where + "." + key;
  std::uint64_t id = 0;
  if (text.size() != 16) throw Refusal{at + " is not 16 hexadecimal digits"};
  for (const char c : text) {
    const int digit = (c >= '0' && c <= '9') ? c - '0' : (c >= 'a' && c <= 'f') ? c - 'a' + 10 : -1;
    if (digit < 0) throw Refusal{at + " is not 16 lower-case hexadecimal digits"};
    id = (id << 4) | static_cast<std::uint64_t>(digit);
  }
  if (id == 0) throw Refusal{at + " is 0"};
  return id;
}

HopRole read_role(const Reader& r, const Json& j, const std::string& where) {
  return r.choice<HopRole>(j, "role", where, {{"publisher", HopRole::publisher}, {"subscriber", HopRole::subscriber}});
}

AnnouncedChannel read_channel(const Reader& r, const Json& j, const std::string& where) {
  AnnouncedChannel c;
  c.name = r.text(j, "name", where, false);
  c.subject = r.whole(j, "subject", where, UINT64_MAX);
  c.cls = r.choice<ChannelClass>(j, "class", where,
                                 {{"hrt", ChannelClass::hrt}, {"srt", ChannelClass::srt}, {"nrt", ChannelClass::nrt}});
  c.verdict = r.choice<Verdict>(
      j, "verdict", where, {{"bound", Verdict::bound}, {"degraded", Verdict::degraded}, {"failed", Verdict::failed}});
  const Json& hops = r.list(j, "hops", where, kMaxAnnouncedHops);
  for (std::size_t i = 0; i < hops.size(); ++i) {
    const std::string at = where + ".hops[" + std::to_string(i) + "]";
    AnnouncedHop h;
    h.segment = r.text(hops[i], "segment", at, false);
    h.role = read_role(r, hops[i], at);
    h.latency = r.nanos_or_unbounded(hops[i], "latency_ns", at);
    c.hops.push_back(std::move(h));
  }
  c.end_to_end = r.nanos_or_unbounded(j, "end_to_end_ns", where);
  c.period = r.nanos_or_unbounded(j, "period_ns", where);
  c.reaction_time = r.nanos_or_unbounded(j, "reaction_time_ns", where);
  c.temp_validity = r.nanos_or_unbounded(j, "temp_validity_ns", where);
  c.payload = r.whole(j, "payload", where, 64ull << 20);
  const Json& upstream = r.list(j, "upstream", where, kMaxAnnouncedHops);
  for (std::size_t i = 0; i < upstream.size(); ++i) {
    const std::string at = where + ".upstream[" + std::to_string(i) + "]";
    PathHop h;
    h.gateway = r.text(upstream[i], "gateway", at, false);
    h.gateway_id = read_id(r, upstream[i], "gateway_id", at);
    h.segment = r.text(upstream[i], "segment", at, false);
    h.role = read_role(r, upstream[i], at);
    h.latency = r.nanos_or_unbounded(upstream[i], "latency_ns", at);
    c.upstream.push_back(std::move(h));
  }
  c.upstream_age = r.nanos_or_unbounded(j, "upstream_ns", where);
  c.violated = r.flag(j, "violated", where);
  return c;
}

Announcement read_announcement(const Json& j) {
  const Reader r;
  if (r.text(j, "format", "announcement", false) != kFederationFormat) {
    throw Refusal{"announcement.format is not " + std::string(kFederationFormat)};
  }
  Announcement a;
  a.gateway = read_id(r, j, "gateway", "announcement");
  a.name = r.text(j, "name", "announcement", false);
  a.revision = r.whole(j, "revision", "announcement", UINT64_MAX);
  a.residence = r.nanos(j, "residence_ns", "announcement");
  const Json& segments = r.list(j, "segments", "announcement", kMaxAnnouncedSegments);
  for (std::size_t i = 0; i < segments.size(); ++i)
    a.segments.push_back(read_segment(r, segments[i], "segments[" + std::to_string(i) + "]"));
  if (!r.field(j, "claim", "announcement").is_null()) {
    const Json& claim = r.list(j, "claim", "announcement", kMaxAnnouncedSegments);
    a.claim.emplace();
    for (std::size_t i = 0; i < claim.size(); ++i)
      a.claim->push_back(read_segment(r, claim[i], "claim[" + std::to_string(i) + "]"));
  }
  const Json& channels = r.list(j, "channels", "announcement", kMaxAnnouncedChannels);
  for (std::size_t i = 0; i < channels.size(); ++i)
    a.channels.push_back(read_channel(r, channels[i], "channels[" + std::to_string(i) + "]"));
  return a;
}

}  // namespace

std::string gateway_id_text(std::uint64_t id) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, id);
  return text;
}

std::string encode(const Announcement& a) {
  Json segments = Json::array();
  for (const auto& s : a.segments) segments.push_back(segment_json(s));
  Json channels = Json::array();
  for (const auto& c : a.channels) channels.push_back(channel_json(c));
  Json claim = nullptr;
  if (a.claim) {
    claim = Json::array();
    for (const auto& s : *a.claim) claim.push_back(segment_json(s));
  }
  const Json j = {{"format", kFederationFormat},
                  {"gateway", gateway_id_text(a.gateway)},
                  {"name", a.name},
                  {"revision", a.revision},
                  {"residence_ns", a.residence.count()},
                  {"segments", segments},
                  {"channels", channels},
                  {"claim", claim}};
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

DecodedAnnouncement decode_announcement(std::string_view text) {
  if (text.size() > kMaxAnnouncementBytes)
    return {std::nullopt, "announcement of " + std::to_string(text.size()) + " bytes, more than 1 MiB"};
  if (!json_nesting_within(text, kMaxNesting))
    return {std::nullopt, "announcement nests deeper than " + std::to_string(kMaxNesting) + " levels"};
  const Json j = Json::parse(text, nullptr, false);
  if (j.is_discarded()) return {std::nullopt, "announcement is not JSON"};
  try {
    return {read_announcement(j), {}};
  } catch (const Refusal& refusal) {
    return {std::nullopt, refusal.why};
  }
}

}  // namespace cosmic

#include "echo_taps.hpp"

#include <cstdio>
#include <span>
#include <vector>

#include "bind_answer.hpp"

namespace cosmic::control_detail {
namespace {

std::string hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  out.reserve(bytes.size() * 2);
  for (const std::uint8_t b : bytes) {
    out.push_back(kDigits[b >> 4]);
    out.push_back(kDigits[b & 0xF]);
  }
  return out;
}

// The tap id a request names, or nullopt.
std::optional<std::uint32_t> tap_of(const nlohmann::json& request) {
  if (!request.contains("tap") || !request["tap"].is_number_unsigned()) return std::nullopt;
  const auto id = request["tap"].get<std::uint64_t>();
  if (id == 0 || id > UINT32_MAX) return std::nullopt;
  return static_cast<std::uint32_t>(id);
}

}  // namespace

EchoTaps::~EchoTaps() {
  for (const auto& entry : open_) gateway_.close_tap(entry.first);
}

EchoTaps::Json EchoTaps::open(const Json& request, Clock::time_point now) {
  if (!request.contains("name") || !request["name"].is_string())
    return failure("bad_request", "echo_open needs \"name\": the channel");
  const std::string name = request["name"].get<std::string>();
  const ChannelSpec* spec = gateway_.knowledge_base().find_bound(name);
  Result<std::uint32_t> tap = gateway_.open_tap(name);
  if (!tap || spec == nullptr) return failure("not_found", tap ? "no bound channel " + name : tap.error().text);
  Open entry{name, nullptr, now};
  if (spec->type) entry.json = std::make_unique<JsonRepresentation>(*spec->type);
  Json answer{{"ok", true}, {"tap", tap.value()}, {"name", name}};
  answer["type"] = spec->type ? Json(describe(*spec->type)) : Json(nullptr);
  open_.emplace(tap.value(), std::move(entry));
  return answer;
}

EchoTaps::Json EchoTaps::read(const Json& request, Clock::time_point now) {
  const auto id = tap_of(request);
  const auto entry = id ? open_.find(*id) : open_.end();
  if (entry == open_.end()) return failure("not_found", "no open tap (echo_open gives one; idle ones close)");
  std::optional<TapRead> taken = gateway_.read_tap(*id);
  if (!taken) {
    open_.erase(entry);
    return failure("not_found", "the tap was closed");
  }
  entry->second.last_read = now;
  Json events = Json::array();
  for (const TappedEvent& event : taken->events) events.push_back(event_json(entry->second, event));
  return Json{{"ok", true}, {"tap", *id}, {"events", std::move(events)}, {"missed", taken->missed}};
}

EchoTaps::Json EchoTaps::close(const Json& request) {
  const auto id = tap_of(request);
  const auto entry = id ? open_.find(*id) : open_.end();
  if (entry == open_.end()) return failure("not_found", "no open tap");
  gateway_.close_tap(*id);
  open_.erase(entry);
  return Json{{"ok", true}};
}

void EchoTaps::expire(Clock::time_point now) {
  for (auto it = open_.begin(); it != open_.end();) {
    if (now - it->second.last_read < kIdleTap) {
      ++it;
      continue;
    }
    gateway_.close_tap(it->first);
    it = open_.erase(it);
  }
}

EchoTaps::Json EchoTaps::event_json(const Open& tap, const TappedEvent& event) const {
  Json out{{"origin", event.header.origin},       {"sequence", event.header.sequence},
           {"hop_count", event.header.hop_count}, {"created_ns", event.header.created_ns},
           {"age_ns", event.header.age_ns},       {"received_ns", event.received_at.count()}};
  if (!tap.json) {
    out["payload"] = hex(event.payload);
    return out;
  }
  // The router checked the event against the type when it took it in: write() refuses only what
  // check_compact refuses, so a refusal here would be a bug; the bytes are shown then.
  std::vector<char> text(tap.json->max_size());
  const std::optional<std::size_t> written = tap.json->write(event.payload, text);
  if (!written) {
    out["payload"] = hex(event.payload);
    return out;
  }
  out["contents"] = Json::parse(std::string_view(text.data(), *written), nullptr, false);
  return out;
}

}  // namespace cosmic::control_detail

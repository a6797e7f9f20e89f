// The structs `cosmicctl gen` writes for typed_gen.yaml, driven by typed_roundtrip.py (which holds
// every expectation): this program only decodes, re-encodes and reports.
//   typed_roundtrip            lines "CHANNEL HEX" on stdin; per line "ok JSON HEX" (the decoded
//                              event as JSON, and it encoded again) or "refused STATUS FIELD"
//   typed_roundtrip refusals   values encode() must refuse, one line "NAME STATUS FIELD" each
// Built against the generated headers only (compact.hpp, scan_type.hpp, diagnostics_type.hpp).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "diagnostics_type.hpp"
#include "scan_type.hpp"

namespace {

const char* status_name(compact::Status status) {
  switch (status) {
    case compact::Status::ok:
      return "ok";
    case compact::Status::over_bound:
      return "over_bound";
    case compact::Status::out_of_range:
      return "out_of_range";
    case compact::Status::not_selected:
      return "not_selected";
    case compact::Status::buffer_too_small:
      return "buffer_too_small";
    case compact::Status::short_event:
      return "short_event";
    case compact::Status::bad_bool:
      return "bad_bool";
    case compact::Status::trailing_bytes:
      return "trailing_bytes";
  }
  return "?";
}

std::string refusal(const compact::Result& result) {
  return std::string(status_name(result.status)) + " " + (*result.field ? result.field : "-");
}

// JSON of the decoded values, as Python's json module reads them back. The records' first: the
// templates below call them for elements.
void json(std::string& out, const types::scan::Event::Pose_& pose);
void json(std::string& out, const types::scan::Event::Track& track);
template <typename T>
void json(std::string& out, const std::vector<T>& values);
template <typename T, std::size_t N>
void json(std::string& out, const std::array<T, N>& values);

void json(std::string& out, bool value) { out += value ? "true" : "false"; }
void json(std::string& out, double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  out += text;
}
void json(std::string& out, float value) { json(out, static_cast<double>(value)); }
void json(std::string& out, const std::string& value) {
  out += '"';
  for (const char c : value) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  out += '"';
}
template <typename T>
requires std::is_integral_v<T>
void json(std::string& out, T value) {
  if constexpr (std::is_signed_v<T>) {
    out += std::to_string(static_cast<long long>(value));
  } else {
    out += std::to_string(static_cast<unsigned long long>(value));
  }
}
template <typename T>
requires std::is_enum_v<T>
void json(std::string& out, T value) { json(out, static_cast<std::underlying_type_t<T>>(value)); }
template <typename T>
void json_list(std::string& out, const T& values) {
  out += '[';
  bool first = true;
  for (const auto& v : values) {
    if (!first) out += ',';
    first = false;
    json(out, v);
  }
  out += ']';
}
template <typename T>
void json(std::string& out, const std::vector<T>& values) {
  json_list(out, values);
}
template <typename T, std::size_t N>
void json(std::string& out, const std::array<T, N>& values) {
  json_list(out, values);
}
template <typename T>
void member(std::string& out, const char* name, const T& value) {
  out += out.back() == '{' ? "\"" : ",\"";
  out += name;
  out += "\":";
  json(out, value);
}
template <typename T>
void member(std::string& out, const char* name, const std::optional<T>& value) {
  if (value) member(out, name, *value);
}

void json(std::string& out, const types::scan::Event::Pose_& pose) {
  out += '{';
  member(out, "x", pose.x);
  member(out, "Pose", pose.Pose);
  member(out, "mode", pose.mode);
  out += '}';
}

void json(std::string& out, const types::scan::Event::Track& track) {
  out += '{';
  member(out, "x", track.x);
  member(out, "tags", track.tags);
  out += '}';
}

void json(std::string& out, const types::scan::Event& e) {
  out += '{';
  member(out, "flag", e.flag);
  member(out, "i8", e.i8);
  member(out, "i16", e.i16);
  member(out, "i32", e.i32);
  member(out, "i64", e.i64);
  member(out, "u8", e.u8);
  member(out, "u16", e.u16);
  member(out, "u32", e.u32);
  member(out, "u64", e.u64);
  member(out, "distance", e.distance);
  member(out, "heading", e.heading);
  member(out, "state", e.state);
  member(out, "label", e.label);
  member(out, "ranges", e.ranges);
  member(out, "corners", e.corners);
  member(out, "flags", e.flags);
  member(out, "names", e.names);
  member(out, "grid", e.grid);
  member(out, "pose", e.pose);
  member(out, "track", e.track);
  member(out, "class", e.class_);
  out += '}';
}

void json(std::string& out, const types::diagnostics::Event& e) {
  out += '{';
  member(out, "Mode", e.Mode);
  member(out, "Dtc", e.Dtc);
  member(out, "Level", e.Level);
  member(out, "Voltage", e.Voltage);
  member(out, "Ignition", e.Ignition);
  out += '}';
}

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
    bytes.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  }
  return bytes;
}

std::string to_hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char two[3];
  for (const std::uint8_t b : bytes) {
    std::snprintf(two, sizeof two, "%02x", b);
    out += two;
  }
  return out.empty() ? "-" : out;
}

// Decodes, and encodes what it decoded.
template <typename Event, typename Decode, typename Encode>
std::string round_trip(const std::vector<std::uint8_t>& bytes, Decode decode, Encode encode) {
  Event event;
  if (const compact::Result decoded = decode(bytes, event); !decoded) return "refused " + refusal(decoded);
  std::string out;
  json(out, event);
  std::vector<std::uint8_t> again;
  if (const compact::Result encoded = encode(event, again); !encoded) return "refused-encode " + refusal(encoded);
  return "ok " + out + " " + to_hex(again);
}

int decode_lines() {
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream words(line);
    std::string channel, hex;
    words >> channel >> hex;
    const auto bytes = from_hex(hex == "-" ? "" : hex);
    if (channel == "scan") {
      std::cout << round_trip<types::scan::Event>(
                       bytes, [](const auto& b, auto& e) { return types::scan::decode(b, e); },
                       [](const auto& e, auto& b) { return types::scan::encode(e, b); })
                << "\n";
    } else {
      std::cout << round_trip<types::diagnostics::Event>(
                       bytes, [](const auto& b, auto& e) { return types::diagnostics::decode(b, e); },
                       [](const auto& e, auto& b) { return types::diagnostics::encode(e, b); })
                << "\n";
    }
  }
  return 0;
}

template <typename Change>
void refuse_scan(const char* name, Change change) {
  types::scan::Event event;
  change(event);
  std::vector<std::uint8_t> bytes;
  std::cout << name << " " << refusal(types::scan::encode(event, bytes)) << "\n";
}

int refusals() {
  using Scan = types::scan::Event;
  refuse_scan("ranges_over_bound", [](Scan& e) { e.ranges = {1, 2, 3, 4}; });
  refuse_scan("label_over_bound", [](Scan& e) { e.label = "123456789"; });
  refuse_scan("tags_over_bound", [](Scan& e) { e.track = {Scan::Track{1.0, {1, 2, 3}}}; });
  refuse_scan("track_over_bound", [](Scan& e) { e.track.resize(Scan::track_max_size + 1); });
  refuse_scan("distance_above", [](Scan& e) { e.distance = 40.5f; });
  refuse_scan("distance_nan", [](Scan& e) { e.distance = std::numeric_limits<float>::quiet_NaN(); });
  refuse_scan("i8_below", [](Scan& e) { e.i8 = -101; });
  refuse_scan("u8_above", [](Scan& e) { e.u8 = 201; });
  refuse_scan("range_element", [](Scan& e) { e.ranges = {1, -1}; });
  refuse_scan("within_bounds", [](Scan& e) { e.ranges.resize(Scan::ranges_max_size); });
  std::array<std::uint8_t, 10> small{};
  std::cout << "buffer_too_small " << refusal(types::scan::encode(Scan{}, std::span<std::uint8_t>(small))) << "\n";
  std::vector<std::uint8_t> bytes;
  types::diagnostics::Event diagnostics;
  diagnostics.Mode = 2;
  diagnostics.Dtc = 1;
  std::cout << "dtc_not_selected " << refusal(types::diagnostics::encode(diagnostics, bytes)) << "\n";
  diagnostics.Dtc.reset();
  diagnostics.Level = 201;
  std::cout << "level_above " << refusal(types::diagnostics::encode(diagnostics, bytes)) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "refusals") return refusals();
  return decode_lines();
}

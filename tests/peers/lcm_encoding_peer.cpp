// cosmic-lcm-encoding-peer FILE.lcm STRUCT [MEMBER=MAX_LENGTH...]: the gateway's LCM representation
// of a struct (cosmic/lcm_representation.hpp) on standard input and output, one JSON request a
// line, one JSON answer a line, so that a test can hold it against lcm-gen's generated code
// (tests/integration/lcm_types/lcm_gen_test.py):
//   {"decode": "HEX"}               -> {"event": {the event as JSON}}
//     (the LCM message to the compact layout, then cosmic::JsonRepresentation)
//   {"encode": {"FIELD": value, ...}} -> {"data": "HEX"}
//     (the fields, every one given, into the compact layout, then the LCM message)
//   {"fingerprint": true}           -> {"fingerprint": "0x...", "describe": "LCM pkg.name_t"}
// A refusal is {"error": "..."}. Exit status 2 when the file, the struct or its type do not read.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/compact_layout.hpp"
#include "cosmic/json_representation.hpp"
#include "cosmic/lcm_representation.hpp"
#include "cosmic/lcm_types.hpp"

namespace {

using Json = nlohmann::json;
using Bytes = std::vector<std::uint8_t>;

std::string to_hex(const Bytes& data) {
  std::string out;
  char byte[3];
  for (const auto b : data) {
    std::snprintf(byte, sizeof byte, "%02x", b);
    out += byte;
  }
  return out;
}

Bytes from_hex(const std::string& hex) {
  Bytes out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  return out;
}

const char* fault_name(cosmic::ConversionFault fault) {
  switch (fault) {
    case cosmic::ConversionFault::none:
      return "none";
    case cosmic::ConversionFault::malformed:
      return "malformed";
    case cosmic::ConversionFault::out_of_range:
      return "out_of_range";
    case cosmic::ConversionFault::too_small:
      return "too_small";
  }
  return "?";
}

void put_u32(std::uint32_t value, Bytes& out) {
  for (int i = 0; i < 4; ++i, value >>= 8) out.push_back(static_cast<std::uint8_t>(value));
}

// One value of the type from JSON into the compact layout (throws on a value of the wrong shape:
// the test's mistake, answered as an error).
void put_value(const cosmic::FieldType& type, const Json& value, Bytes& out) {
  using Kind = cosmic::FieldType::Kind;
  switch (type.kind) {
    case Kind::scalar:
    case Kind::enumeration: {
      cosmic::ScalarValue v;
      if (type.scalar == cosmic::ScalarKind::boolean) {
        v.unsigned_integer = value.get<bool>() ? 1 : 0;
      } else if (type.scalar == cosmic::ScalarKind::float32 || type.scalar == cosmic::ScalarKind::float64) {
        v.real = value.get<double>();
      } else if (cosmic::is_signed_integer(type.scalar)) {
        v.integer = value.get<std::int64_t>();
      } else {
        v.unsigned_integer = value.get<std::uint64_t>();
      }
      out.resize(out.size() + cosmic::scalar_size(type.scalar));
      cosmic::write_scalar(type.scalar, v, out.data() + out.size() - cosmic::scalar_size(type.scalar));
      return;
    }
    case Kind::string: {
      const auto text = value.get<std::string>();
      put_u32(static_cast<std::uint32_t>(text.size()), out);
      out.insert(out.end(), text.begin(), text.end());
      return;
    }
    case Kind::sequence:
      put_u32(static_cast<std::uint32_t>(value.size()), out);
      [[fallthrough]];
    case Kind::array:
      for (const Json& element : value) put_value(type.element.at(0), element, out);
      return;
    case Kind::record:
      for (const cosmic::TypeField& f : type.fields) put_value(f.type, value.at(f.name), out);
      return;
  }
}

struct Peer {
  cosmic::ChannelType type;
  cosmic::LcmRepresentation lcm;
  cosmic::JsonRepresentation json;
};

Json decode(const Peer& peer, const std::string& hex) {
  Bytes event(peer.lcm.max_compact_size());
  const auto read = peer.lcm.to_compact(from_hex(hex), event);
  if (!read.ok()) return Json{{"error", fault_name(read.fault)}};
  event.resize(read.size);
  std::string text(peer.json.max_size(), '\0');
  const auto size = peer.json.write(event, std::span<char>(text.data(), text.size()));
  if (!size) return Json{{"error", "the event is not one JSON writes"}};
  return Json{{"event", Json::parse(text.substr(0, *size))}};
}

Json encode(const Peer& peer, const Json& fields) {
  Bytes event;
  for (const cosmic::TypeField& f : peer.type.fields) put_value(f.type, fields.at(f.name), event);
  if (const auto checked = cosmic::check_compact(peer.type, event); !checked)
    return Json{{"error", checked.error().text}};
  Bytes wire(peer.lcm.max_wire_size());
  const auto written = peer.lcm.from_compact(event, wire);
  if (!written.ok()) return Json{{"error", fault_name(written.fault)}};
  wire.resize(written.size);
  return Json{{"data", to_hex(wire)}};
}

Json answer(const Peer& peer, const Json& request) {
  if (request.contains("decode")) return decode(peer, request["decode"].get<std::string>());
  if (request.contains("encode")) return encode(peer, request["encode"]);
  if (request.contains("fingerprint")) {
    char text[19];
    std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(peer.lcm.fingerprint()));
    return Json{{"fingerprint", text}, {"describe", peer.lcm.describe()}};
  }
  return Json{{"error", "unknown request"}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: cosmic-lcm-encoding-peer FILE.lcm STRUCT [MEMBER=MAX_LENGTH...]\n";
    return 64;
  }
  std::ifstream in(argv[1], std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const cosmic::LcmTypeFile file = cosmic::parse_lcm_types(text.str());
  const cosmic::LcmStruct* s = file.find(argv[2]);
  if (!in || !file.ok() || s == nullptr) {
    for (const auto& e : file.errors)
      std::cerr << argv[1] << ":" << e.line << ":" << e.column << ": " << e.message << "\n";
    std::cerr << argv[1] << ": no struct " << argv[2] << " read\n";
    return 2;
  }
  std::map<std::string, std::uint32_t> max_length;
  for (int i = 3; i < argc; ++i) {
    const std::string bound = argv[i];
    const auto equals = bound.find('=');
    max_length[bound.substr(0, equals)] = static_cast<std::uint32_t>(std::stoul(bound.substr(equals + 1)));
  }
  const cosmic::LcmChannelType typed = cosmic::lcm_channel_type(file, *s, max_length);
  if (!typed.ok()) {
    std::cerr << typed.errors.front().message << "\n";
    return 2;
  }
  auto made = cosmic::LcmRepresentation::make(file, *s, typed.type);
  if (!made) {
    std::cerr << made.error().text << "\n";
    return 2;
  }
  const Peer peer{typed.type, std::move(made).value(), cosmic::JsonRepresentation(cosmic::ChannelType(typed.type))};
  std::string line;
  while (std::getline(std::cin, line)) {
    Json reply;
    try {
      reply = answer(peer, Json::parse(line));
    } catch (const std::exception& e) {  // a malformed request from the test: say so, go on
      reply = Json{{"error", e.what()}};
    }
    std::cout << reply.dump() << std::endl;
  }
  return 0;
}

// cosmic-dbc-codec-peer DBC_FILE: the gateway's DBC reader and codec (cosmic/dbc.hpp,
// cosmic/dbc_codec.hpp) on standard input and output, one JSON request a line, one JSON answer a
// line, so that a test can hold them against an implementation we did not write
// (tests/integration/dbc/canmatrix_test.py, python3-canmatrix):
//   {"decode": "MESSAGE", "data": "HEX"}        -> {"values": {"SIGNAL": physical, ...}, "raw": {"SIGNAL": raw, ...}}
//     (only the signals the frame carries: a multiplexed one when its switch selects it)
//   {"encode": "MESSAGE", "values": {"SIGNAL": physical, ...}}  -> {"data": "HEX"}
//     (the signals not given are 0 bits; a value the signal cannot hold is {"error": "..."})
//   {"type": "MESSAGE"}                          -> {"type": "<describe() of the channel type>"}
// and through the typed channel's representations (cosmic/dbc_frames.hpp, cosmic/json_representation.hpp):
//   {"json": "MESSAGE", "data": "HEX"}          -> {"json": {the event as JSON}}
//     (the frame to the compact layout, then JSON)
//   {"pack": "MESSAGE", "fields": {"FIELD": number, ...}}  -> {"data": "HEX"}
//     (the fields into the compact layout, an enumeration at its raw value, then the frame; a field
//      not given is 0; {"error": ...} for a value out of range, which is dropped)
// Exit status 2 when the DBC file does not read.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/dbc.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/dbc_codec.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/json_representation.hpp"

namespace {

using Json = nlohmann::json;

const cosmic::DbcMessage* find(const cosmic::DbcFile& file, const std::string& name) {
  for (const auto& m : file.messages) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::string to_hex(const std::vector<std::uint8_t>& data) {
  std::string out;
  char byte[3];
  for (const auto b : data) {
    std::snprintf(byte, sizeof byte, "%02x", b);
    out += byte;
  }
  return out;
}

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  return out;
}

Json decode(const cosmic::DbcMessage& m, const std::string& hex) {
  std::vector<std::uint8_t> data = from_hex(hex);
  data.resize(m.length);
  Json values = Json::object();
  Json raw = Json::object();
  for (const auto& s : m.signals) {
    if (!cosmic::dbc_signal_present(m, s, data)) continue;
    const std::uint64_t bits = cosmic::dbc_read_bits(s, data);
    values[s.name] = cosmic::dbc_physical(s, bits);
    if (s.value_type == cosmic::DbcValueType::integer) {
      raw[s.name] = s.is_signed ? Json(cosmic::dbc_raw_integer(s, bits)) : Json(bits);
    }
  }
  return Json{{"values", values}, {"raw", raw}};
}

Json encode(const cosmic::DbcMessage& m, const Json& values) {
  std::vector<std::uint8_t> data(m.length, 0);
  for (const auto& [name, value] : values.items()) {
    const auto signal = std::find_if(m.signals.begin(), m.signals.end(), [&](const auto& s) { return s.name == name; });
    if (signal == m.signals.end()) return Json{{"error", "no signal " + name}};
    const auto bits = cosmic::dbc_bits_for(*signal, value.get<double>());
    if (!bits) return Json{{"error", "signal " + name + " cannot hold " + value.dump()}};
    cosmic::dbc_write_bits(*signal, *bits, data);
  }
  return Json{{"data", to_hex(data)}};
}

Json typed_json(const cosmic::DbcMessage& m, const std::string& hex) {
  const auto type = cosmic::channel_type_from_dbc(m).type;
  const auto codec = cosmic::DbcFrameCodec::make(m, type);
  if (!codec) return Json{{"error", codec.error().text}};
  std::vector<std::uint8_t> frame = from_hex(hex);
  frame.resize(m.length);
  std::vector<std::uint8_t> compact(codec.value().compact_size());
  if (!codec.value().to_compact(frame, compact)) return Json{{"error", "short frame"}};
  const cosmic::JsonRepresentation json{cosmic::ChannelType(type)};
  std::string text(json.max_size(), '\0');
  const auto size = json.write(compact, std::span<char>(text.data(), text.size()));
  if (!size) return Json{{"error", "not an event"}};
  return Json{{"json", Json::parse(text.substr(0, *size))}};
}

Json typed_pack(const cosmic::DbcMessage& m, const Json& fields) {
  const auto type = cosmic::channel_type_from_dbc(m).type;
  const auto codec = cosmic::DbcFrameCodec::make(m, type);
  const auto layout = cosmic::CompactLayout::of_flat_record(type);
  if (!codec || !layout) return Json{{"error", "no typed codec"}};
  std::vector<std::uint8_t> compact(layout.value().size());
  for (std::size_t i = 0; i < type.fields.size(); ++i) {
    if (!fields.contains(type.fields[i].name)) continue;
    const Json& given = fields[type.fields[i].name];
    const auto& slot = layout.value().slots()[i];
    cosmic::ScalarValue value;
    if (slot.kind == cosmic::ScalarKind::float32 || slot.kind == cosmic::ScalarKind::float64) {
      value.real = given.get<double>();
    } else if (cosmic::is_signed_integer(slot.kind)) {
      value.integer = given.get<std::int64_t>();
    } else {
      value.unsigned_integer = given.get<std::uint64_t>();
    }
    cosmic::write_scalar(slot.kind, value, compact.data() + slot.offset);
  }
  std::vector<std::uint8_t> frame(m.length);
  const auto packed = codec.value().to_frame(compact, frame, cosmic::RangePolicy::drop);
  if (!packed.sent) return Json{{"error", std::to_string(packed.out_of_range) + " out of range"}};
  return Json{{"data", to_hex(frame)}};
}

Json answer(const cosmic::DbcFile& file, const Json& request) {
  for (const char* verb : {"decode", "encode", "type", "json", "pack"}) {
    if (!request.contains(verb)) continue;
    const cosmic::DbcMessage* m = find(file, request[verb].get<std::string>());
    if (m == nullptr) return Json{{"error", "no message " + request[verb].get<std::string>()}};
    if (std::string(verb) == "decode") return decode(*m, request.at("data").get<std::string>());
    if (std::string(verb) == "encode") return encode(*m, request.at("values"));
    if (std::string(verb) == "json") return typed_json(*m, request.at("data").get<std::string>());
    if (std::string(verb) == "pack") return typed_pack(*m, request.at("fields"));
    const auto typed = cosmic::channel_type_from_dbc(*m);
    return typed.ok() ? Json{{"type", cosmic::describe(typed.type)}} : Json{{"error", typed.errors.front().message}};
  }
  return Json{{"error", "unknown request"}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: cosmic-dbc-codec-peer DBC_FILE\n";
    return 64;
  }
  std::ifstream in(argv[1], std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const cosmic::DbcFile file = cosmic::parse_dbc(text.str());
  if (!in || !file.ok()) {
    for (const auto& e : file.errors)
      std::cerr << argv[1] << ":" << e.line << ":" << e.column << ": " << e.message << "\n";
    return 2;
  }
  std::string line;
  while (std::getline(std::cin, line)) {
    Json reply;
    try {
      reply = answer(file, Json::parse(line));
    } catch (const std::exception& e) {  // a malformed request from the test: say so, go on
      reply = Json{{"error", e.what()}};
    }
    std::cout << reply.dump() << std::endl;
  }
  return 0;
}

// The C++ side of mcap_interop.cjs's npm-decodes-cdr check (issue 37: typed messages decode with
// @foxglove/rosmsg2-serialization to the values sent):
//   mcap_cdr_sample FILE.mcap EXPECTED.json
// writes an MCAP file as the recorder does under `typed_encoding: cdr`: one channel of
// ros2_msg_test::every_kind() (every scalar kind, enumerations, strings, arrays, bounded sequences,
// nested records), its schema the type's ROS 2 message definition (encoding ros2msg), its messages
// the events CdrRepresentation writes in XCDR1 (encoding cdr). EXPECTED.json holds, per message,
// the values it carries as a ROS 2 decoder gives them back: enumerations as their numbers, 64-bit
// integers as decimal strings (beyond a double), an array of arrays as one flat array.
// Exit status: 0, 1 when a value does not convert or a file cannot be written, 64 on bad usage.
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../unit/mcap_test_support.hpp"
#include "../unit/ros2_msg_test_types.hpp"
#include "cosmic/cdr_representation.hpp"
#include "cosmic/json_event_reader.hpp"
#include "cosmic/ros2_msg_schema.hpp"

namespace {

using json = nlohmann::ordered_json;  // the fields in their order, as the decoder gives them

// The events sent, as JsonEventReader reads them (enumerations by name or number). Extremes of
// every integer kind, float32 values a float holds exactly, strings and sequences empty and full.
const char* const kEvents[] = {
    R"({"flag":true,"i8":-128,"i16":-32768,"i32":-2147483648,"i64":-9223372036854775808,"u8":255,"u16":65535,
        "u32":4294967295,"u64":18446744073709551615,"f32":-1.5,"f64":0.1,"state":"OFF","gear":"HUGE",
        "label":"abcdefgh","ranges":[0.25,1,2.5,40],"grid":[[1,2,3],[4,5,6]],"track":[-7,0,7],
        "pose":{"x":1.25,"y":-2.5,"heading":3.0},"path":[{"name":"a","stamp":1},{"name":"wxyz","stamp":4000000000}],
        "mode":9,"direction":"REVERSE","power":"ON","fix":{"origin":{"lat":48.1,"lon":11.6},"quality":4},
        "corners":[{"x":-1,"light":"ON"},{"x":2,"light":0}],"names":["left","right"],"flags":[true,false,true,true]})",
    R"({"flag":false,"i8":127,"i16":32767,"i32":2147483647,"i64":9007199254740993,"u8":0,"u16":0,"u32":0,
        "u64":9007199254740993,"f32":3.4028234663852886e38,"f64":-1e300,"state":"RUN","gear":"LOW","label":"",
        "ranges":[0,0,0,0],"grid":[[0,0,0],[0,0,255]],"track":[],"pose":{"x":0,"y":0,"heading":-0.5},"path":[],
        "mode":0,"direction":"FORWARD","power":"OFF","fix":{"origin":{"lat":-90,"lon":180},"quality":0},
        "corners":[{"x":32767,"light":"OFF"},{"x":-32768,"light":"ON"}],"names":["","12345"],"flags":[]})",
    R"({"flag":true,"i8":0,"i16":1,"i32":-1,"i64":0,"u8":1,"u16":2,"u32":3,"u64":4,"f32":0,"f64":5e-324,
        "state":7,"gear":3,"label":"mid","ranges":[1,2,3,4],"grid":[[9,8,7],[6,5,4]],"track":[1],
        "pose":{"x":-1,"y":1,"heading":0},"path":[{"name":"","stamp":0}],"mode":1,"direction":42,"power":"ON",
        "fix":{"origin":{"lat":0,"lon":0},"quality":255},"corners":[{"x":0,"light":"OFF"},{"x":1,"light":"OFF"}],
        "names":["x","y"],"flags":[false]})",
};

// `value` (of field type `type`) as a ROS 2 decoder returns it, in JSON.
json decoded(const cosmic::FieldType& type, const json& value) {
  using Kind = cosmic::FieldType::Kind;
  using cosmic::ScalarKind;
  switch (type.kind) {
    case Kind::scalar:
    case Kind::enumeration: {
      json number = value;
      if (value.is_string()) {  // a named value
        for (const cosmic::EnumValue& v : type.values)
          if (v.name == value.get<std::string>()) number = v.value;
      }
      if (type.scalar == ScalarKind::int64 || type.scalar == ScalarKind::uint64) return number.dump();
      return number;
    }
    case Kind::string:
      return value;
    case Kind::array:
    case Kind::sequence: {
      // An array of arrays is decoded as one flat array (cosmic/ros2_msg_schema.hpp).
      json out = json::array();
      for (const json& element : value) {
        const json inner = decoded(type.element.at(0), element);
        if (type.element.at(0).kind == Kind::array) {
          out.insert(out.end(), inner.begin(), inner.end());
        } else {
          out.push_back(inner);
        }
      }
      return out;
    }
    case Kind::record: {
      json out = json::object();
      for (const cosmic::TypeField& f : type.fields) out[f.name] = decoded(f.type, value.at(f.name));
      return out;
    }
  }
  return value;
}

int write_cdr_sample(const char* mcap_path, const char* json_path) {
  using namespace cosmic;
  const ChannelType type = ros2_msg_test::every_kind();
  const auto schema = ros2_msg_schema(type, "every-kind");
  auto cdr = CdrRepresentation::make(type, DdsRepresentation::xcdr1, CdrExtensibility::final_type);
  if (!schema || !cdr) {
    std::cerr << "mcap_cdr_sample: " << (!schema ? schema.error().text : cdr.error().text) << "\n";
    return 1;
  }
  mcap_test::Written written;
  auto writer = McapWriter::open(mcap_test::small_chunks(McapCompression::zstd, 4096), mcap_test::sink_into(written));
  const auto& text = schema.value().text;
  auto schema_id = writer ? writer.value().add_schema(schema.value().name, "ros2msg",
                                                      {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()})
                          : Result<std::uint16_t>(Error{"no writer"});
  auto channel_id = schema_id ? writer.value().add_channel(schema_id.value(), "every-kind", "cdr", {})
                              : Result<std::uint16_t>(schema_id.error());
  if (!channel_id) {
    std::cerr << "mcap_cdr_sample: " << channel_id.error().text << "\n";
    return 1;
  }
  const JsonEventReader reader{ChannelType(type)};
  FieldType whole;
  whole.kind = FieldType::Kind::record;
  whole.fields = type.fields;
  json expected{{"schemaName", schema.value().name}, {"values", json::array()}};
  std::uint32_t sequence = 0;
  for (const char* event : kEvents) {
    std::vector<std::uint8_t> compact(reader.max_compact_size());
    const auto read = reader.read(event, compact);
    if (!read) {
      std::cerr << "mcap_cdr_sample: " << read.error().text << "\n";
      return 1;
    }
    std::vector<std::uint8_t> sample(cdr.value().max_wire_size());
    const Conversion written_sample = cdr.value().from_compact(std::span(compact).first(read.value()), sample);
    if (!written_sample.ok()) {
      std::cerr << "mcap_cdr_sample: an event did not convert to CDR\n";
      return 1;
    }
    sample.resize(written_sample.size);
    ++sequence;
    if (!writer.value().write_message(channel_id.value(), sequence, sequence * 1'000'000ull, sequence, sample))
      return 1;
    expected["values"].push_back(decoded(whole, json::parse(event)));
  }
  if (!writer.value().finish()) return 1;
  std::ofstream mcap(mcap_path, std::ios::binary);
  mcap.write(reinterpret_cast<const char*>(written.file.data()), static_cast<std::streamsize>(written.file.size()));
  std::ofstream out(json_path);
  out << expected << "\n";
  if (!mcap || !out) {
    std::cerr << "mcap_cdr_sample: cannot write " << mcap_path << " or " << json_path << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3) return write_cdr_sample(argv[1], argv[2]);
  std::cerr << "usage: mcap_cdr_sample FILE.mcap EXPECTED.json\n";
  return 64;
}

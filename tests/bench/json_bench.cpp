// cosmic_json_bench: Google Benchmark figures of typed events as JSON (issue 37: a recording holds
// millions of events, each read back by replay). Prints figures; never a pass/fail target. One
// event of 10 fields (integers, floats, an enumeration, a bool, a string, an array of 3 doubles):
//
//   BM_ReadJson           JsonEventReader::read_unexplained of the text write() gives (the
//                         forwarding path and replay: fields in order, no allocation)
//   BM_ReadJsonShuffled   the same text with its fields in reverse order and whitespace, as
//                         another producer may write it (each field skipped once, then read)
//   BM_ReadJsonExplained  JsonEventReader::read (the Result type, no refusal)
//   BM_ParseNlohmann      nlohmann::json::parse of the same text into its DOM, for comparison:
//                         what reading with nlohmann-json would cost before any conversion
//   BM_WriteJson          JsonRepresentation::write of the event
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cosmic/json_event_reader.hpp"
#include "cosmic/json_representation.hpp"

namespace {

using cosmic::ChannelType;
using cosmic::FieldType;
using cosmic::ScalarKind;
using cosmic::TypeField;

TypeField bench_field(std::string name, FieldType type) {
  TypeField f;
  f.name = std::move(name);
  f.type = std::move(type);
  return f;
}

FieldType bench_scalar(ScalarKind kind) {
  FieldType t;
  t.scalar = kind;
  return t;
}

ChannelType ten_fields() {
  FieldType state = bench_scalar(ScalarKind::uint8);
  state.kind = FieldType::Kind::enumeration;
  state.values = {{"OFF", 0}, {"IDLE", 1}, {"RUN", 2}};
  FieldType label;
  label.kind = FieldType::Kind::string;
  label.bound = 16;
  FieldType position;
  position.kind = FieldType::Kind::array;
  position.bound = 3;
  position.element = {bench_scalar(ScalarKind::float64)};
  ChannelType type;
  type.fields = {bench_field("stamp", bench_scalar(ScalarKind::uint64)),
                 bench_field("speed", bench_scalar(ScalarKind::float64)),
                 bench_field("accel", bench_scalar(ScalarKind::float32)),
                 bench_field("gear", bench_scalar(ScalarKind::int8)),
                 bench_field("state", state),
                 bench_field("valid", bench_scalar(ScalarKind::boolean)),
                 bench_field("label", label),
                 bench_field("position", position),
                 bench_field("odometer", bench_scalar(ScalarKind::uint32)),
                 bench_field("temperature", bench_scalar(ScalarKind::int16))};
  return type;
}

const std::string kTenFields =
    R"({"stamp":1700000000123456789,"speed":12.345678901234567,"accel":-0.10000000149011612,"gear":-1,)"
    R"("state":"RUN","valid":true,"label":"front-left","position":[1.5,-2.25,1e-3],"odometer":123456,)"
    R"("temperature":-40})";
const std::string kTenFieldsShuffled =
    R"({ "temperature": -40, "odometer": 123456, "position": [1.5, -2.25, 1e-3], "label": "front-left",)"
    R"( "valid": true, "state": "RUN", "gear": -1, "accel": -0.10000000149011612,)"
    R"( "speed": 12.345678901234567, "stamp": 1700000000123456789 })";

void read_bench(benchmark::State& state, const std::string& text) {
  const cosmic::JsonEventReader reader{ten_fields()};
  std::vector<std::uint8_t> compact(reader.max_compact_size());
  for (auto _ : state) {
    auto size = reader.read_unexplained(text, compact);
    if (!size) state.SkipWithError("refused");
    benchmark::DoNotOptimize(size);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}

void BM_ReadJson(benchmark::State& state) { read_bench(state, kTenFields); }
BENCHMARK(BM_ReadJson);

void BM_ReadJsonShuffled(benchmark::State& state) { read_bench(state, kTenFieldsShuffled); }
BENCHMARK(BM_ReadJsonShuffled);

void BM_ReadJsonExplained(benchmark::State& state) {
  const cosmic::JsonEventReader reader{ten_fields()};
  std::vector<std::uint8_t> compact(reader.max_compact_size());
  for (auto _ : state) {
    auto size = reader.read(kTenFields, compact);
    if (!size.ok()) state.SkipWithError("refused");
    benchmark::DoNotOptimize(size);
  }
}
BENCHMARK(BM_ReadJsonExplained);

void BM_ParseNlohmann(benchmark::State& state) {
  for (auto _ : state) {
    nlohmann::json parsed = nlohmann::json::parse(kTenFields);
    benchmark::DoNotOptimize(parsed);
  }
}
BENCHMARK(BM_ParseNlohmann);

void BM_WriteJson(benchmark::State& state) {
  const cosmic::JsonEventReader reader{ten_fields()};
  std::vector<std::uint8_t> compact(reader.max_compact_size());
  compact.resize(reader.read_unexplained(kTenFields, compact).value_or(0));
  const cosmic::JsonRepresentation writer{ten_fields()};
  std::string out(writer.max_size(), '\0');
  for (auto _ : state) {
    auto size = writer.write(compact, std::span<char>(out.data(), out.size()));
    benchmark::DoNotOptimize(size);
  }
}
BENCHMARK(BM_WriteJson);

}  // namespace

BENCHMARK_MAIN();

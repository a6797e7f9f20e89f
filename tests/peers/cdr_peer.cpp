// cosmic-cdr-peer: cosmic::CdrRepresentation (cosmic/cdr_representation.hpp) on the channel type that
// reads as the IDL of tests/integration/dds/cyclone/cdr_check.idl, for the CDR cross-check against
// Cyclone DDS (cdr_check_test.sh; the other side is cyclone_cdr_peer.c, whose sample values this
// computes the same way).
//
//   cosmic-cdr-peer decode   lines "K EXT VERSION ORDER HEX" on stdin (Cyclone's samples): each must
//                            read (to_compact, by every variant: the sample says its encoding) as
//                            sample K's event exactly, and a little-endian one must be written back
//                            (from_compact) as the very same bytes. One line per sample on stdout.
//   cosmic-cdr-peer encode   sample K of each variant (final XCDR1, final XCDR2, appendable XCDR2)
//                            as from_compact writes it, one such line each, for the Cyclone peer.
//   cosmic-cdr-peer idl-...  the type read from an IDL file instead (cdr_peer_idl.cpp), for the
//                            cross-check of the IDL reader against idlc (tests/integration/idl_types).
//
// Exit 0: every sample agreed (decode) or was written (encode); 1: one did not; 2: bad arguments.
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "peer_hex.hpp"
#include "cosmic/cdr_representation.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;
namespace peer = cosmic::peer;
using cosmic::FieldType;
using cosmic::ScalarKind;

constexpr int kSamples = 3;
const char* const kNames[kSamples] = {"", "abc", "abcdefgh"};
const char* const kLabels[kSamples][2] = {{"", "wxyz"}, {"a", "bc"}, {"hi", ""}};

FieldType scalar(ScalarKind kind) {
  FieldType t;
  t.scalar = kind;
  return t;
}
FieldType text(std::uint32_t bound) {
  FieldType t;
  t.kind = FieldType::Kind::string;
  t.bound = bound;
  return t;
}
FieldType collection(FieldType::Kind kind, FieldType element, std::uint32_t bound) {
  FieldType t;
  t.kind = kind;
  t.bound = bound;
  t.element = {std::move(element)};
  return t;
}
FieldType record(std::vector<cosmic::TypeField> fields) {
  FieldType t;
  t.kind = FieldType::Kind::record;
  t.fields = std::move(fields);
  return t;
}
cosmic::TypeField field(std::string name, FieldType type) {
  cosmic::TypeField f;
  f.name = std::move(name);
  f.type = std::move(type);
  return f;
}

// cdrcheck::Sample (and cdrcheck_app::Sample) as a channel's type.
cosmic::ChannelType sample_type() {
  FieldType state;
  state.kind = FieldType::Kind::enumeration;
  state.scalar = ScalarKind::int32;  // an IDL enum
  state.values = {{"STATE_OFF", 0}, {"STATE_ON", 1}, {"STATE_FAULT", 2}};
  const FieldType point = record({field("x", scalar(ScalarKind::int16)), field("y", scalar(ScalarKind::uint8))});
  const FieldType vec = record({field("x", scalar(ScalarKind::float64)), field("y", scalar(ScalarKind::float64)),
                                field("z", scalar(ScalarKind::float64))});
  using K = FieldType::Kind;
  return cosmic::ChannelType{
      {field("small", scalar(ScalarKind::int8)), field("flag", scalar(ScalarKind::uint8)),
       field("big", scalar(ScalarKind::int64)), field("on", scalar(ScalarKind::boolean)), field("name", text(8)),
       field("points", collection(K::sequence, point, 4)),
       field("grid", collection(K::array, collection(K::array, scalar(ScalarKind::float64), 3), 2)), field("pose", vec),
       field("stamps", collection(K::sequence, scalar(ScalarKind::int64), 3)), field("tail", scalar(ScalarKind::uint8)),
       field("mode", state), field("modes", collection(K::sequence, state, 3)),
       field("labels", collection(K::array, text(4), 2)),
       field("bits", collection(K::sequence, scalar(ScalarKind::boolean), 4)),
       field("ratio", scalar(ScalarKind::float32)), field("count", scalar(ScalarKind::uint16)),
       field("id", scalar(ScalarKind::uint32)), field("last", scalar(ScalarKind::uint8))},
      std::nullopt};
}

class Event {
 public:
  Event& number(std::uint64_t v, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  Event& f64(double v) { return number(std::bit_cast<std::uint64_t>(v), 8); }
  Event& f32(float v) { return number(std::bit_cast<std::uint32_t>(v), 4); }
  Event& str(const std::string& s) {
    number(s.size(), 4);
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    return *this;
  }
  Bytes bytes() const { return bytes_; }

 private:
  Bytes bytes_;
};

// Sample k's event in the compact layout: the values of cyclone_cdr_peer.c's FILL_SAMPLE.
Bytes sample_event(int k) {
  Event e;
  e.number(static_cast<std::uint64_t>(-3 - k), 1).number(200 + k, 1);
  e.number(static_cast<std::uint64_t>(-1234567890123LL * (k + 1)), 8).number(k % 2, 1).str(kNames[k]);
  const int points = (2 * k) % 5;
  e.number(points, 4);
  for (int i = 0; i < points; ++i) e.number(static_cast<std::uint64_t>(-100 * i - k), 2).number(i + 10 * k, 1);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) e.f64(i * 10 + j + 0.5 * k);
  }
  e.f64(k + 0.25).f64(-k - 0.5).f64(1e10 + k);
  e.number(k, 4);
  for (int i = 0; i < k; ++i) e.number(std::uint64_t{1} << (40 + i + k), 8);
  e.number(0xA0 + k, 1).number(k % 3, 4);
  e.number(k + 1, 4);
  for (int i = 0; i < k + 1; ++i) e.number((i + k) % 3, 4);
  e.str(kLabels[k][0]).str(kLabels[k][1]);
  e.number(k + 2, 4);
  for (int i = 0; i < k + 2; ++i) e.number((i + k) % 2, 1);
  e.f32(1.5f + static_cast<float>(k)).number(65535 - k, 2).number(4000000000u + static_cast<unsigned>(k), 4);
  e.number(0x5A + k, 1);
  return e.bytes();
}

struct Variant {
  const char* extensibility;
  const char* version;
};
constexpr Variant kVariants[] = {{"final", "xcdr1"}, {"final", "xcdr2"}, {"appendable", "xcdr2"}};

cosmic::CdrRepresentation representation(const std::string& extensibility, const std::string& version) {
  auto made = cosmic::CdrRepresentation::make(
      sample_type(), version == "xcdr2" ? cosmic::DdsRepresentation::xcdr2 : cosmic::DdsRepresentation::xcdr1,
      extensibility == "appendable" ? cosmic::CdrExtensibility::appendable : cosmic::CdrExtensibility::final_type);
  if (!made) {
    std::fprintf(stderr, "cdr-peer: %s\n", made.error().text.c_str());
    std::exit(1);
  }
  return std::move(made).value();
}

Bytes written(const cosmic::CdrRepresentation& cdr, const Bytes& event) {
  Bytes wire(cdr.max_wire_size());
  const cosmic::Conversion c = cdr.from_compact(event, wire);
  wire.resize(c.ok() ? c.size : 0);
  return wire;
}

// Why Cyclone's sample `wire` of sample k does not agree with ours, or empty.
std::string disagreement(const std::string& extensibility, const std::string& version, bool little_endian, int k,
                         const Bytes& wire) {
  const Bytes want = sample_event(k);
  for (const Variant& v : kVariants) {
    const cosmic::CdrRepresentation cdr = representation(v.extensibility, v.version);
    Bytes event(cdr.max_compact_size());
    const cosmic::Conversion c = cdr.to_compact(wire, event);
    event.resize(c.size);
    if (!c.ok()) return std::string("refused (fault ") + std::to_string(static_cast<int>(c.fault)) + ")";
    if (event != want) return "read other values: " + peer::hex(event) + " instead of " + peer::hex(want);
  }
  const Bytes ours = written(representation(extensibility, version), want);
  if (little_endian && ours != wire) return "we write " + peer::hex(ours);
  return "";
}

int decode() {
  std::string line;
  int failures = 0, samples = 0;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    int k = -1;
    std::string extensibility, version, order, text;
    if (!(in >> k >> extensibility >> version >> order >> text) || k < 0 || k >= kSamples) {
      std::fprintf(stderr, "cdr-peer: bad line: %s\n", line.c_str());
      return 2;
    }
    const std::string why = disagreement(extensibility, version, order == "le", k, peer::unhex(text));
    std::printf("%s %d %s %s %s %s\n", why.empty() ? "ok" : "FAIL", k, extensibility.c_str(), version.c_str(),
                order.c_str(), why.c_str());
    failures += why.empty() ? 0 : 1;
    ++samples;
  }
  return failures == 0 && samples > 0 ? 0 : 1;
}

int encode() {
  for (const Variant& v : kVariants) {
    const cosmic::CdrRepresentation cdr = representation(v.extensibility, v.version);
    for (int k = 0; k < kSamples; ++k) {
      const Bytes wire = written(cdr, sample_event(k));
      if (wire.empty()) return 1;
      std::printf("%d %s %s le %s\n", k, v.extensibility, v.version, peer::hex(wire).c_str());
    }
  }
  return 0;
}

}  // namespace

int idl_main(int argc, char** argv);  // cdr_peer_idl.cpp

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]).starts_with("idl-")) return idl_main(argc, argv);
  const std::string mode = argc == 2 ? argv[1] : "";
  if (mode == "decode") return decode();
  if (mode == "encode") return encode();
  std::fprintf(stderr, "usage: cosmic-cdr-peer decode|encode|idl-check|idl-type|idl-samples|idl-decode ...\n");
  return 2;
}

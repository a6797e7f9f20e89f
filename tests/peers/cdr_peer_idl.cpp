// cosmic-cdr-peer's IDL modes (cdr_peer.cpp dispatches to idl_main): a type read from an IDL file
// with cosmic::parse_idl_types (cosmic/idl_types.hpp) instead of the built-in one, for the
// cross-check against Cyclone's idlc (tests/integration/idl_types/idlc_check_test.py; the other
// side is cyclone_idl_peer.c, built on the C code idlc generates for the same file).
//
//   idl-check   INCLUDE_DIR FILE
//       reads FILE (its #includes from INCLUDE_DIR, as idlc -I reads them); prints "ok" and every
//       struct's scoped name, or each error as "FILE:LINE:COL: message". Exit 0 when it read.
//   idl-type    INCLUDE_DIR FILE NAME [PATH=N...]
//       the struct's channel type (describe()) and its extensibility, or the errors.
//   idl-samples INCLUDE_DIR FILE NAME VERSION COUNT [PATH=N...]
//       COUNT samples of the struct (values from a fixed seed per sample, within the bounds),
//       written by CdrRepresentation in VERSION (xcdr1, xcdr2) and the struct's extensibility:
//       one line each, "K VERSION HEX TEXT", TEXT the values as Cyclone's ddsi_serdata_print
//       shows them ({...} per struct, array and sequence, the dimensions of an array of arrays
//       flattened into one, enums and chars as numbers, floats as %g, strings in quotes).
//   idl-decode  INCLUDE_DIR FILE NAME [PATH=N...]
//       lines "K VERSION HEX" on stdin (Cyclone's samples): each must read as sample K's values
//       exactly, and written back in VERSION be the very same bytes. One line per sample, "ok ..."
//       or "FAIL ... why".
//
// PATH=N bounds a string or sequence (max_length of idl_channel_type). Exit 0: every sample
// agreed (or was written); 1: one did not, or the file or type was refused; 2: bad arguments.
#include <bit>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "peer_hex.hpp"
#include "cosmic/cdr_representation.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/idl_types.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;
namespace peer = cosmic::peer;
using cosmic::FieldType;
using cosmic::ScalarKind;

std::optional<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct IdlInput {
  cosmic::IdlTypeFile file;
  std::string path;
};

IdlInput read_idl(const std::string& include_dir, const std::string& path) {
  const auto text = read_text(path);
  if (!text) {
    IdlInput input;
    input.file.errors.push_back(cosmic::IdlError{"", 0, 0, "cannot read " + path});
    return input;
  }
  const cosmic::IdlIncludeLoader load = [&include_dir](std::string_view name) {
    return read_text(include_dir + "/" + std::string(name));
  };
  return IdlInput{cosmic::parse_idl_types(*text, load), path};
}

void print_errors(const std::vector<cosmic::IdlError>& errors, const std::string& root) {
  for (const cosmic::IdlError& e : errors) {
    std::printf("%s:%d:%d: %s\n", e.file.empty() ? root.c_str() : e.file.c_str(), e.line, e.column, e.message.c_str());
  }
}

// The struct NAME's channel type with PATH=N bounds from args[first...]; nullopt (errors printed).
std::optional<cosmic::IdlChannelType> channel_type(const IdlInput& input, const std::string& name, char** args,
                                                   int count) {
  std::map<std::string, std::uint32_t> max_length;
  for (int i = 0; i < count; ++i) {
    const std::string arg = args[i];
    const auto eq = arg.find('=');
    if (eq == std::string::npos) return std::nullopt;
    max_length[arg.substr(0, eq)] = static_cast<std::uint32_t>(std::stoul(arg.substr(eq + 1)));
  }
  if (!input.file.ok()) {
    print_errors(input.file.errors, input.path);
    return std::nullopt;
  }
  const cosmic::IdlStruct* s = input.file.find(name);
  if (s == nullptr) {
    std::printf("%s: no struct %s\n", input.path.c_str(), name.c_str());
    return std::nullopt;
  }
  cosmic::IdlChannelType typed = cosmic::idl_channel_type(input.file, *s, max_length);
  if (!typed.ok()) {
    print_errors(typed.errors, input.path);
    return std::nullopt;
  }
  return typed;
}

// Sample k: its event in the compact layout and its values as Cyclone prints them. An appendable
// struct in XCDR2 starts with its DHEADER, which Cyclone prints as "dlh:N" right before the first
// member: written "dlh:#" here (the test matches any N; the sizes are the CDR writer's business).
class SampleMaker {
 public:
  SampleMaker(int k, bool appendable)
      : random_(static_cast<std::uint32_t>(20261201 + 7919 * k)), appendable_(appendable) {}

  void record(const std::vector<cosmic::TypeField>& fields) {
    text_ += appendable_ ? "{dlh:#" : "{";
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (i > 0) text_ += ",";
      value(fields[i].type);
    }
    text_ += "}";
  }

  const Bytes& event() const { return event_; }
  const std::string& text() const { return text_; }

 private:
  void value(const FieldType& t) {
    switch (t.kind) {
      case FieldType::Kind::scalar:
        return scalar(t.scalar);
      case FieldType::Kind::enumeration: {
        const auto& named = t.values[random_() % t.values.size()];
        number(static_cast<std::uint64_t>(named.value), cosmic::scalar_size(t.scalar));
        text_ += std::to_string(named.value);
        return;
      }
      case FieldType::Kind::string:
        return string(t.bound);
      case FieldType::Kind::array: {
        bool first = true;
        text_ += "{";
        array_items(t, first);
        text_ += "}";
        return;
      }
      case FieldType::Kind::sequence:
        return sequence(t);
      case FieldType::Kind::record:
        return record(t.fields);
    }
  }

  // An array's elements, those of an array of arrays as one list (as Cyclone prints them).
  void array_items(const FieldType& t, bool& first) {
    for (std::uint32_t i = 0; i < t.bound; ++i) {
      if (t.element[0].kind == FieldType::Kind::array) {
        array_items(t.element[0], first);
        continue;
      }
      if (!first) text_ += ",";
      first = false;
      value(t.element[0]);
    }
  }

  void sequence(const FieldType& t) {
    const std::uint32_t length = random_() % (std::min<std::uint32_t>(t.bound, 4) + 1);
    number(length, 4);
    text_ += "{";
    for (std::uint32_t i = 0; i < length; ++i) {
      if (i > 0) text_ += ",";
      value(t.element[0]);
    }
    text_ += "}";
  }

  void string(std::uint32_t bound) {
    static const char kLetters[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    const std::uint32_t length = random_() % (std::min<std::uint32_t>(bound, 12) + 1);
    number(length, 4);
    text_ += "\"";
    for (std::uint32_t i = 0; i < length; ++i) {
      const char c = kLetters[random_() % (sizeof kLetters - 1)];
      event_.push_back(static_cast<std::uint8_t>(c));
      text_ += c;
    }
    text_ += "\"";
  }

  void scalar(ScalarKind kind) {
    char buffer[64];
    if (kind == ScalarKind::float32 || kind == ScalarKind::float64) {
      const double v = static_cast<double>(static_cast<int>(random_() % 80001) - 40000) * 0.125;
      if (kind == ScalarKind::float32) {
        number(std::bit_cast<std::uint32_t>(static_cast<float>(v)), 4);
      } else {
        number(std::bit_cast<std::uint64_t>(v), 8);
      }
      std::snprintf(buffer, sizeof buffer, "%g", v);
      text_ += buffer;
      return;
    }
    const std::size_t size = cosmic::scalar_size(kind);
    const std::uint64_t bits = (std::uint64_t{random_()} << 32) | random_();
    const std::uint64_t v = kind == ScalarKind::boolean ? bits & 1
                            : size == 8                 ? bits
                                                        : bits & ((std::uint64_t{1} << (8 * size)) - 1);
    number(v, size);
    if (kind == ScalarKind::boolean) {
      text_ += v ? "true" : "false";
    } else if (cosmic::is_signed_integer(kind)) {
      const unsigned shift = static_cast<unsigned>(64 - 8 * size);
      text_ += std::to_string(static_cast<std::int64_t>(v << shift) >> shift);
    } else {
      text_ += std::to_string(v);
    }
  }

  void number(std::uint64_t v, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) event_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }

  std::mt19937 random_;
  bool appendable_;
  Bytes event_;
  std::string text_;
};

std::optional<cosmic::CdrRepresentation> representation(const cosmic::IdlChannelType& typed,
                                                        const std::string& version) {
  auto made = cosmic::CdrRepresentation::make(
      typed.type, version == "xcdr2" ? cosmic::DdsRepresentation::xcdr2 : cosmic::DdsRepresentation::xcdr1,
      typed.extensibility);
  if (!made) {
    std::printf("CdrRepresentation refused the type: %s\n", made.error().text.c_str());
    return std::nullopt;
  }
  return std::move(made).value();
}

int samples(const cosmic::IdlChannelType& typed, const std::string& version, int count) {
  const auto cdr = representation(typed, version);
  if (!cdr) return 1;
  const bool appendable = typed.extensibility == cosmic::CdrExtensibility::appendable && version == "xcdr2";
  for (int k = 0; k < count; ++k) {
    SampleMaker sample(k, appendable);
    sample.record(typed.type.fields);
    Bytes wire(cdr->max_wire_size());
    const cosmic::Conversion c = cdr->from_compact(sample.event(), wire);
    if (!c.ok()) {
      std::printf("FAIL %d: from_compact fault %d\n", k, static_cast<int>(c.fault));
      return 1;
    }
    wire.resize(c.size);
    std::printf("%d %s %s %s\n", k, version.c_str(), peer::hex(wire).c_str(), sample.text().c_str());
  }
  return 0;
}

// Why Cyclone's sample `wire` of sample k disagrees with ours, or empty.
std::string disagreement(const cosmic::IdlChannelType& typed, const std::string& version, int k, const Bytes& wire) {
  const auto cdr = representation(typed, version);
  if (!cdr) return "no representation";
  SampleMaker sample(k, false);
  sample.record(typed.type.fields);
  Bytes event(cdr->max_compact_size());
  const cosmic::Conversion read = cdr->to_compact(wire, event);
  if (!read.ok()) return "refused (fault " + std::to_string(static_cast<int>(read.fault)) + ")";
  event.resize(read.size);
  if (event != sample.event())
    return "read other values: " + peer::hex(event) + " instead of " + peer::hex(sample.event());
  Bytes ours(cdr->max_wire_size());
  const cosmic::Conversion write = cdr->from_compact(sample.event(), ours);
  ours.resize(write.ok() ? write.size : 0);
  if (ours != wire) return "we write " + peer::hex(ours);
  return "";
}

int decode(const cosmic::IdlChannelType& typed) {
  std::string line;
  int failures = 0, count = 0;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    int k = -1;
    std::string version, text;
    if (!(in >> k >> version >> text) || k < 0) {
      std::fprintf(stderr, "cdr-peer: bad line: %s\n", line.c_str());
      return 2;
    }
    const std::string why = disagreement(typed, version, k, peer::unhex(text));
    std::printf("%s %d %s %s\n", why.empty() ? "ok" : "FAIL", k, version.c_str(), why.c_str());
    failures += why.empty() ? 0 : 1;
    ++count;
  }
  return failures == 0 && count > 0 ? 0 : 1;
}

int check(const IdlInput& input) {
  if (!input.file.ok()) {
    print_errors(input.file.errors, input.path);
    return 1;
  }
  std::printf("ok\n");
  for (const cosmic::IdlStruct& s : input.file.structs) std::printf("%s\n", s.name.c_str());
  return 0;
}

}  // namespace

int idl_main(int argc, char** argv) {
  const std::string mode = argv[1];
  if (argc < 4) return 2;
  const IdlInput input = read_idl(argv[2], argv[3]);
  if (mode == "idl-check") return check(input);
  if (argc < 5) return 2;
  const int extra = mode == "idl-samples" ? 2 : 0;
  if (argc < 5 + extra) return 2;
  const auto typed = channel_type(input, argv[4], argv + 5 + extra, argc - 5 - extra);
  if (!typed) return 1;
  if (mode == "idl-type") {
    std::printf("%s%s\n", typed->extensibility == cosmic::CdrExtensibility::appendable ? "@appendable " : "@final ",
                cosmic::describe(typed->type).c_str());
    return 0;
  }
  if (mode == "idl-samples") return samples(*typed, argv[5], std::atoi(argv[6]));
  if (mode == "idl-decode") return decode(*typed);
  return 2;
}

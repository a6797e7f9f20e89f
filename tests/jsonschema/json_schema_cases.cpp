// cosmic-json-schema-cases OUT_DIR: for each type of schema_test_types.hpp writes
//   OUT_DIR/NAME.schema.json    json_schema(type, NAME)
//   OUT_DIR/NAME.events.jsonl   kEventsPerCase events, one JSON text a line, as JsonRepresentation
//                               writes them from the compact layout
// for validate.cjs to hold against ajv, a validator we did not write (run_ajv.sh). The events are
// made deterministically (a fixed seed per case) and lean on the edges: each integer kind's lowest
// and highest, NaN, infinities and float32's limits, values beyond declared ranges, unnamed
// enumeration values, empty and full strings and sequences, invalid UTF-8, control characters and
// quotes, and conditional fields both carried and left out. Exit status 1 when an event made here
// is not one JsonRepresentation writes (a fault of this tool), 2 on wrong usage.
#include <bit>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/json_representation.hpp"
#include "cosmic/json_schema.hpp"
#include "schema_test_types.hpp"

namespace {

using cosmic::FieldType;
using cosmic::ScalarKind;
using cosmic::TypeField;
using Bytes = std::vector<std::uint8_t>;

constexpr int kEventsPerCase = 120;

// Pieces strings are made of: ASCII, what JSON escapes, valid UTF-8 of 2 to 4 bytes, and bytes that
// are not UTF-8 (a lone continuation, a lead byte alone, a surrogate, an overlong form, beyond
// U+10FFFF), each written as U+FFFD.
constexpr std::string_view kStringPieces[] = {"a",
                                              "Z",
                                              "7",
                                              " ",
                                              "\"",
                                              "\\",
                                              "\n",
                                              "\x01",
                                              "\x1f",
                                              "\x7f",
                                              "\x80",
                                              "\xc0",
                                              "\xff",
                                              "\xc3",
                                              "\xc3\xa9",
                                              "\xe2\x82\xac",
                                              "\xe2\x80\xa8",
                                              "\xf0\x9f\x98\x80",
                                              "\xed\xa0\x80",
                                              "\xe0\x80\x80",
                                              "\xf4\x90\x80\x80",
                                              std::string_view("\0", 1)};

class EventMaker {
 public:
  explicit EventMaker(std::uint64_t seed) : random_(seed) {}

  Bytes event(const cosmic::ChannelType& type) {
    bytes_.clear();
    record(type.fields);
    return bytes_;
  }

 private:
  std::uint64_t below(std::uint64_t n) { return random_() % n; }

  void record(const std::vector<TypeField>& fields) {
    std::vector<std::int64_t> values(fields.size(), 0);
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const TypeField& f = fields[i];
      if (f.present_when && values[selector_index(fields, f.present_when->selector)] != f.present_when->value) {
        zero(f.type);  // not selected: its place holds zero bits
        continue;
      }
      values[i] = value(f.type, selecting_values(fields, f.name));
    }
  }

  static std::size_t selector_index(const std::vector<TypeField>& fields, const std::string& name) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (fields[i].name == name) return i;
    }
    return 0;
  }

  // The values of `name` that select a conditional field of the record.
  static std::vector<std::int64_t> selecting_values(const std::vector<TypeField>& fields, const std::string& name) {
    std::vector<std::int64_t> out;
    for (const TypeField& f : fields) {
      if (f.present_when && f.present_when->selector == name) out.push_back(f.present_when->value);
    }
    return out;
  }

  // One value of `type` appended; an integer's (or enumeration's) value returned, as JsonWriter
  // reads selectors (an unsigned value cast to int64).
  std::int64_t value(const FieldType& type, const std::vector<std::int64_t>& selects) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
        return scalar(type.scalar, selects);
      case FieldType::Kind::enumeration: {
        if (below(2) == 0) return scalar(type.scalar, selects);
        const std::int64_t named = type.values[below(type.values.size())].value;
        // The named value, or a neighbour (named or not) within the kind.
        return put_integer(type.scalar, static_cast<std::uint64_t>(named) + (below(3) == 0 ? below(3) - 1 : 0));
      }
      case FieldType::Kind::string: {
        const std::uint32_t length = count(type.bound);
        std::string text;
        while (text.size() < length) {
          const std::string_view piece = kStringPieces[below(std::size(kStringPieces))];
          text += piece.size() <= length - text.size() ? piece : std::string_view("\xff");
        }
        put_count(length);
        bytes_.insert(bytes_.end(), text.begin(), text.end());
        return 0;
      }
      case FieldType::Kind::array:
        for (std::uint32_t i = 0; i < type.bound; ++i) value(type.element[0], {});
        return 0;
      case FieldType::Kind::sequence: {
        const std::uint32_t elements = count(type.bound);
        put_count(elements);
        for (std::uint32_t i = 0; i < elements; ++i) value(type.element[0], {});
        return 0;
      }
      case FieldType::Kind::record:
        record(type.fields);
        return 0;
    }
    return 0;
  }

  // Empty, full, or anything between.
  std::uint32_t count(std::uint32_t bound) {
    const std::uint64_t choice = below(4);
    return choice == 0 ? 0 : choice == 1 ? bound : static_cast<std::uint32_t>(below(std::uint64_t{bound} + 1));
  }

  void put_count(std::uint32_t count) { put_integer(ScalarKind::uint32, count); }

  std::int64_t scalar(ScalarKind kind, const std::vector<std::int64_t>& selects) {
    if (kind == ScalarKind::float32) return put_real(kind, float32_value());
    if (kind == ScalarKind::float64) return put_real(kind, float64_value());
    if (kind == ScalarKind::boolean) return put_integer(kind, below(2));
    if (!selects.empty() && below(2) == 0) {
      // A value that selects a conditional field, or one beside it.
      const std::int64_t selecting = selects[below(selects.size())];
      return put_integer(kind, static_cast<std::uint64_t>(selecting) + (below(3) == 0 ? below(3) - 1 : 0));
    }
    const std::size_t bits = cosmic::scalar_size(kind) * 8;
    const std::uint64_t sign = cosmic::is_signed_integer(kind) ? std::uint64_t{1} << (bits - 1) : 0;
    const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    const std::uint64_t lowest = sign;          // two's complement bits of the kind's lowest
    const std::uint64_t highest = mask ^ sign;  // ... and highest
    switch (below(6)) {
      case 0:
        return put_integer(kind, lowest);
      case 1:
        return put_integer(kind, highest);
      case 2:
        return put_integer(kind, 0);
      case 3:
        return put_integer(kind, below(2) == 0 ? lowest + 1 : highest - 1);
      default:
        return put_integer(kind, random_());
    }
  }

  // Two's complement bits, cut to the kind's size; the value as JsonWriter's selectors see it.
  std::int64_t put_integer(ScalarKind kind, std::uint64_t bits) {
    const std::size_t size = cosmic::scalar_size(kind);
    cosmic::ScalarValue v;
    v.unsigned_integer = size == 8 ? bits : bits & ((std::uint64_t{1} << (size * 8)) - 1);
    v.integer = static_cast<std::int64_t>(v.unsigned_integer);
    if (cosmic::is_signed_integer(kind) && size < 8 && (v.unsigned_integer >> (size * 8 - 1)) != 0) {
      v.integer -= std::int64_t{1} << (size * 8);  // sign-extended
    }
    append(kind, v);
    return cosmic::is_signed_integer(kind) ? v.integer : static_cast<std::int64_t>(v.unsigned_integer);
  }

  std::int64_t put_real(ScalarKind kind, double real) {
    cosmic::ScalarValue v;
    v.real = real;
    append(kind, v);
    return 0;
  }

  void append(ScalarKind kind, const cosmic::ScalarValue& v) {
    const std::size_t at = bytes_.size();
    bytes_.resize(at + cosmic::scalar_size(kind));
    cosmic::write_scalar(kind, v, bytes_.data() + at);
  }

  double float32_value() {
    using Limits = std::numeric_limits<float>;
    static constexpr float kEdges[] = {Limits::quiet_NaN(),
                                       Limits::infinity(),
                                       -Limits::infinity(),
                                       -0.0f,  // written as -0
                                       Limits::max(),
                                       -Limits::max(),
                                       Limits::denorm_min(),
                                       0.1f,
                                       45.5f,  // beyond the declared 0..40 of every_kind's f32
                                       -1.0f};
    if (below(3) == 0) return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(random_())));
    return static_cast<double>(kEdges[below(std::size(kEdges))]);
  }

  double float64_value() {
    using Limits = std::numeric_limits<double>;
    static constexpr double kEdges[] = {Limits::quiet_NaN(),
                                        Limits::infinity(),
                                        -Limits::infinity(),
                                        -0.0,
                                        Limits::max(),
                                        -Limits::max(),
                                        Limits::denorm_min(),
                                        0.1,
                                        -2.5,
                                        1e300};
    if (below(3) == 0) return std::bit_cast<double>(random_());
    return kEdges[below(std::size(kEdges))];
  }

  // Makes the zero bits of a value its selector does not select.
  void zero(const FieldType& type) {
    switch (type.kind) {
      case FieldType::Kind::scalar:
      case FieldType::Kind::enumeration:
        bytes_.resize(bytes_.size() + cosmic::scalar_size(type.scalar));
        break;
      case FieldType::Kind::string:
      case FieldType::Kind::sequence:
        put_count(0);
        break;
      case FieldType::Kind::array:
        for (std::uint32_t i = 0; i < type.bound; ++i) zero(type.element[0]);
        break;
      case FieldType::Kind::record:
        for (const TypeField& f : type.fields) zero(f.type);
        break;
    }
  }

  std::mt19937_64 random_;  // its sequence is fixed by the standard, whatever the library
  Bytes bytes_;
};

struct Case {
  std::string name;
  cosmic::ChannelType type;
};

bool write_case(const std::string& directory, const Case& c, std::uint64_t seed) {
  std::ofstream schema(directory + "/" + c.name + ".schema.json", std::ios::binary);
  schema << cosmic::json_schema(c.type, c.name) << '\n';
  std::ofstream events(directory + "/" + c.name + ".events.jsonl", std::ios::binary);
  const cosmic::JsonRepresentation json{cosmic::ChannelType(c.type)};
  std::string out(json.max_size(), '\0');
  EventMaker maker(seed);
  for (int i = 0; i < kEventsPerCase; ++i) {
    const Bytes compact = maker.event(c.type);
    const auto written = json.write(compact, std::span<char>(out.data(), out.size()));
    if (!written) {
      std::fprintf(stderr, "%s: event %d is not one JsonRepresentation writes (%s)\n", c.name.c_str(), i,
                   cosmic::check_compact(c.type, compact).ok()
                       ? "no room"
                       : cosmic::check_compact(c.type, compact).error().text.c_str());
      return false;
    }
    events.write(out.data(), static_cast<std::streamsize>(*written)) << '\n';
  }
  return static_cast<bool>(schema) && static_cast<bool>(events);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: cosmic-json-schema-cases OUT_DIR\n");
    return 2;
  }
  namespace t = cosmic::schema_test;
  const Case cases[] = {{"every_kind", t::every_kind()},
                        {"diagnostics", t::dbc_message_type("Diagnostics")},
                        {"status", t::dbc_message_type("Status")},
                        {"nested_conditional", t::nested_conditional()},
                        {"strings", t::strings()}};
  std::uint64_t seed = 37;
  for (const Case& c : cases) {
    if (!cosmic::check_type(c.type).empty()) {
      std::fprintf(stderr, "%s: not a sound type: %s\n", c.name.c_str(), cosmic::check_type(c.type)[0].what.c_str());
      return 1;
    }
    if (!write_case(argv[1], c, seed++)) return 1;
  }
  return 0;
}

// LCM structs' fingerprints and their types as typed channels' contents (cosmic/lcm_types.hpp).
// The hash is lcm-gen's: over each member's name, a primitive member's type name and the
// dimensions (mode and size as written), never the struct's own name, in 64-bit two's complement
// with an arithmetic shift; the fingerprint adds the nested structs' fingerprints and rotates left
// by one, as lcm-gen's generated _get_hash_recursive does.
#include "cosmic/lcm_types.hpp"

#include <algorithm>
#include <limits>
#include <set>

#include "cosmic/units.hpp"

namespace cosmic {
namespace {

std::int64_t hash_update(std::int64_t v, char c) {
  // lcm-gen: v = ((v << 8) ^ (v >> 55)) + c, on int64_t, the shift right arithmetic.
  const auto shifted = static_cast<std::int64_t>(static_cast<std::uint64_t>(v) << 8);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(shifted ^ (v >> 55)) +
                                   static_cast<std::uint64_t>(static_cast<std::int64_t>(static_cast<signed char>(c))));
}

std::int64_t hash_string(std::int64_t v, std::string_view s) {
  v = hash_update(v, static_cast<char>(s.size()));
  for (const char c : s) v = hash_update(v, c);
  return v;
}

std::uint64_t rotate_left_one(std::uint64_t v) { return (v << 1) | (v >> 63); }

// Nested structs reachable from `s` (by full name), or the first name missing or on a cycle.
struct Reach {
  std::vector<const LcmStruct*> order;  // children before parents
  std::optional<std::string> missing, cycle;
};

void visit(const LcmTypeFile& file, const LcmStruct& s, std::set<std::string>& on_path, std::set<std::string>& done,
           Reach& reach) {
  if (reach.missing || reach.cycle) return;
  on_path.insert(s.full_name());
  for (const LcmMember& m : s.members) {
    if (lcm_is_primitive(m.type) || done.count(m.type)) continue;
    if (on_path.count(m.type)) {
      reach.cycle = m.type;
      return;
    }
    const LcmStruct* nested = file.find(m.type);
    if (nested == nullptr) {
      reach.missing = m.type;
      return;
    }
    visit(file, *nested, on_path, done, reach);
  }
  on_path.erase(s.full_name());
  done.insert(s.full_name());
  reach.order.push_back(&s);
}

Reach reach_of(const LcmTypeFile& file, const LcmStruct& s) {
  Reach reach;
  std::set<std::string> on_path, done;
  visit(file, s, on_path, done, reach);
  return reach;
}

FieldType primitive(std::string_view type) {
  FieldType t;
  t.kind = FieldType::Kind::scalar;
  if (type == "int8_t") t.scalar = ScalarKind::int8;
  if (type == "int16_t") t.scalar = ScalarKind::int16;
  if (type == "int32_t") t.scalar = ScalarKind::int32;
  if (type == "int64_t") t.scalar = ScalarKind::int64;
  if (type == "byte") t.scalar = ScalarKind::uint8;
  if (type == "float") t.scalar = ScalarKind::float32;
  if (type == "double") t.scalar = ScalarKind::float64;
  if (type == "boolean") t.scalar = ScalarKind::boolean;
  if (type == "string") {
    t.kind = FieldType::Kind::string;
    t.bound = kLcmStringBound;
  }
  return t;
}

// The most elements a variable dimension sized by an integer of `count_type` can have.
std::uint32_t count_limit(std::string_view count_type) {
  if (count_type == "int8_t") return 127;
  if (count_type == "int16_t") return 32'767;
  return kLcmSequenceBound;
}

class TypeBuilder {
 public:
  TypeBuilder(const LcmTypeFile& file, const std::map<std::string, std::uint32_t>& max_length, LcmChannelType& out)
      : file_(file), max_length_(max_length), out_(out) {}

  std::vector<TypeField> record(const LcmStruct& s, std::size_t depth, bool top) {
    std::vector<TypeField> fields;
    for (const LcmMember& m : s.members) {
      TypeField f;
      f.name = m.name;
      const auto element = element_type(m, depth);
      if (!element) continue;
      f.type = *element;
      // Outermost dimension first: double grid[2][n] is an array of 2 sequences of n.
      for (auto d = m.dimensions.rbegin(); d != m.dimensions.rend(); ++d) f.type = dimension(s, m, *d, f.type, top);
      fields.push_back(std::move(f));
    }
    return fields;
  }

 private:
  std::optional<FieldType> element_type(const LcmMember& m, std::size_t depth) {
    if (lcm_is_primitive(m.type)) return primitive(m.type);
    if (depth + 1 >= kMaxTypeDepth) {
      out_.errors.push_back(
          LcmError{m.line, m.column,
                   "member " + m.name + " nests structs more than " + std::to_string(kMaxTypeDepth) + " deep"});
      return std::nullopt;
    }
    const LcmStruct* nested = file_.find(m.type);
    if (nested == nullptr) return std::nullopt;  // reported by lcm_channel_type
    FieldType t;
    t.kind = FieldType::Kind::record;
    t.fields = record(*nested, depth + 1, false);
    return t;
  }

  FieldType dimension(const LcmStruct& s, const LcmMember& m, const LcmDimension& d, const FieldType& inner, bool top) {
    FieldType t;
    t.element = {inner};
    if (!d.variable) {
      t.kind = FieldType::Kind::array;
      t.bound = static_cast<std::uint32_t>(std::stoul(d.size));
      return t;
    }
    t.kind = FieldType::Kind::sequence;
    const auto count =
        std::find_if(s.members.begin(), s.members.end(), [&](const LcmMember& c) { return c.name == d.size; });
    t.bound = count_limit(count == s.members.end() ? "" : count->type);
    if (const auto given = max_length_.find(m.name); top && given != max_length_.end()) {
      if (given->second < 1 || given->second > t.bound) {
        out_.errors.push_back(LcmError{m.line, m.column,
                                       "max_length " + std::to_string(given->second) + " of " + m.name + " is not 1.." +
                                           std::to_string(t.bound) + " (what " + d.size + " holds)"});
      } else {
        t.bound = given->second;
      }
    }
    return t;
  }

  const LcmTypeFile& file_;
  const std::map<std::string, std::uint32_t>& max_length_;
  LcmChannelType& out_;
};

}  // namespace

std::int64_t lcm_base_hash(const LcmStruct& s) {
  std::int64_t v = 0x12345678;
  for (const LcmMember& m : s.members) {
    v = hash_string(v, m.name);
    if (lcm_is_primitive(m.type)) v = hash_string(v, m.type);
    v = hash_update(v, static_cast<char>(m.dimensions.size()));
    for (const LcmDimension& d : m.dimensions) {
      v = hash_update(v, d.variable ? 1 : 0);
      v = hash_string(v, d.size);
    }
  }
  return v;
}

std::optional<std::uint64_t> lcm_fingerprint(const LcmTypeFile& file, const LcmStruct& s) {
  const Reach reach = reach_of(file, s);
  if (reach.missing || reach.cycle) return std::nullopt;
  // Without cycles a struct's fingerprint does not depend on who asks: compute each once, children first.
  std::map<std::string, std::uint64_t> done;
  for (const LcmStruct* each : reach.order) {
    std::uint64_t hash = static_cast<std::uint64_t>(lcm_base_hash(*each));
    for (const LcmMember& m : each->members) {
      if (!lcm_is_primitive(m.type)) hash += done.at(m.type);
    }
    done[each->full_name()] = rotate_left_one(hash);
  }
  return done.at(s.full_name());
}

LcmChannelType lcm_channel_type(const LcmTypeFile& file, const LcmStruct& s,
                                const std::map<std::string, std::uint32_t>& max_length) {
  LcmChannelType out;
  const Reach reach = reach_of(file, s);
  if (reach.missing || reach.cycle) {
    const std::string what = reach.missing ? "struct " + *reach.missing + " is not defined in the file"
                                           : "struct " + *reach.cycle + " contains itself";
    out.errors.push_back(LcmError{s.line, s.column, s.full_name() + ": " + what});
    return out;
  }
  for (const auto& entry : max_length) {
    const std::string& name = entry.first;  // (clang-14: no structured binding in a lambda's capture)
    const auto member =
        std::find_if(s.members.begin(), s.members.end(), [&](const LcmMember& m) { return m.name == name; });
    const bool variable = member != s.members.end() && std::any_of(member->dimensions.begin(), member->dimensions.end(),
                                                                   [](const LcmDimension& d) { return d.variable; });
    if (!variable) {
      out.errors.push_back(LcmError{s.line, s.column,
                                    "max_length names " + name +
                                        ", which is not a variable-length "
                                        "array member of " +
                                        s.full_name()});
    }
  }
  out.type.fields = TypeBuilder(file, max_length, out).record(s, 0, true);
  if (!out.errors.empty()) return out;
  for (const TypeProblem& p : check_type(out.type)) {
    // The usual cause: LCM's variable-length arrays are unbounded, so each counts at its limit.
    const bool too_big = p.what.find("scalars") != std::string::npos;
    out.errors.push_back(LcmError{s.line, s.column,
                                  s.full_name() + ": " + (p.where.empty() ? "" : p.where + ": ") + p.what +
                                      (too_big ? " (max_length: {MEMBER: N} bounds a variable-length array)" : "")});
  }
  return out;
}

}  // namespace cosmic

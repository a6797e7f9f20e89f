// An IDL struct as a typed channel's contents (cosmic/idl_types.hpp): the ChannelType whose CDR
// form (cosmic/cdr_representation.hpp) is the struct's. Members in order are the fields; a nested
// struct is a record; an enum an enumeration of int32 (4 bytes, as CDR writes an enum); a typedef
// stands for its type; `T a[2][3]` an array of 2 arrays of 3; sequences and strings keep their
// bounds, the unbounded ones get max_length's or kMaxTypeBound.
#include <algorithm>
#include <set>

#include "cosmic/idl_types.hpp"

namespace cosmic {
namespace idl_build {
namespace {

std::string extensibility_word(CdrExtensibility e) {
  return e == CdrExtensibility::appendable ? "@appendable" : "@final";
}

class TypeBuilder {
 public:
  TypeBuilder(const IdlTypeFile& file, const IdlStruct& top, const std::map<std::string, std::uint32_t>& max_length,
              IdlChannelType& out)
      : top_(top), max_length_(max_length), out_(out) {
    for (const IdlStruct& s : file.structs) structs_[s.name] = &s;
    for (const IdlEnum& e : file.enums) enums_[e.name] = &e;
    for (const IdlTypedef& t : file.typedefs) typedefs_[t.name] = &t;
  }

  std::vector<TypeField> record(const IdlStruct& s, const std::string& path, std::size_t depth) {
    std::vector<TypeField> fields;
    for (const IdlMember& m : s.members) {
      if (failed_) break;
      const Place at{&s, &m, path.empty() ? m.name : path + "." + m.name};
      auto type = member_type(m.type, m.dimensions, at, depth);
      if (!type) continue;
      TypeField f;
      f.name = m.name;
      f.type = std::move(*type);
      f.unit = m.unit;
      f.minimum = m.minimum;
      f.maximum = m.maximum;
      fields.push_back(std::move(f));
    }
    return fields;
  }

  // The paths max_length named that no string or sequence has.
  std::vector<std::string> unused_max_length() const {
    std::vector<std::string> out;
    for (const auto& entry : max_length_) {
      if (!used_.count(entry.first)) out.push_back(entry.first);
    }
    return out;
  }

 private:
  // Where a type is built: the member it belongs to (for locations) and its max_length path.
  struct Place {
    const IdlStruct* owner;
    const IdlMember* member;
    std::string path;
  };

  void error(const Place& at, std::string message) {
    out_.errors.push_back(IdlError{at.owner->file, at.member->line, at.member->column,
                                   "member " + at.member->name + " of " + at.owner->name + ": " + std::move(message)});
  }

  // Counts the type nodes built; false (reported once) past the budget, so that structs nesting
  // structs many times over cannot cost without limit.
  bool spend(const Place& at) {
    if (++nodes_ <= kIdlMaxTypeNodes) return true;
    if (!failed_) {
      error(at, top_.name + " expands to more than " + std::to_string(kIdlMaxTypeNodes) +
                    " types (nested structs counted at every use)");
    }
    failed_ = true;
    return false;
  }

  std::optional<FieldType> member_type(const IdlType& type, const std::vector<std::uint32_t>& dimensions,
                                       const Place& at, std::size_t depth) {
    // The innermost element is built with the path of the elements ("names[]" for string names[3]).
    Place inner = at;
    for (std::size_t i = 0; i < dimensions.size(); ++i) inner.path += "[]";
    auto element = field_type(type, inner, depth + dimensions.size());
    if (!element) return std::nullopt;
    for (auto d = dimensions.rbegin(); d != dimensions.rend(); ++d) {
      FieldType array;
      array.kind = FieldType::Kind::array;
      array.bound = *d;
      array.element = {std::move(*element)};
      element = std::move(array);
    }
    return element;
  }

  std::optional<FieldType> field_type(const IdlType& type, const Place& at, std::size_t depth) {
    if (!spend(at)) return std::nullopt;
    if (depth >= kMaxTypeDepth) {
      error(at,
            "types nest more than " + std::to_string(kMaxTypeDepth) + " deep (structs, arrays, sequences, typedefs)");
      return std::nullopt;
    }
    switch (type.kind) {
      case IdlType::Kind::primitive: {
        FieldType t;
        t.scalar = type.scalar;
        return t;
      }
      case IdlType::Kind::string:
      case IdlType::Kind::sequence:
        return bounded(type, at, depth);
      case IdlType::Kind::structure:
        return nested(type, at, depth);
      case IdlType::Kind::enumeration:
        return enumeration(type);
      case IdlType::Kind::alias:
        return alias(type, at, depth);
    }
    return std::nullopt;
  }

  std::optional<FieldType> bounded(const IdlType& type, const Place& at, std::size_t depth) {
    FieldType t;
    t.kind = type.kind == IdlType::Kind::string ? FieldType::Kind::string : FieldType::Kind::sequence;
    t.bound = type.bound == 0 ? kMaxTypeBound : std::min(type.bound, kMaxTypeBound + 1);
    const auto given = max_length_.find(at.path);
    if (given == max_length_.end()) {
      if (type.bound > kMaxTypeBound) {
        error(at, "bound " + std::to_string(type.bound) + " is beyond " + std::to_string(kMaxTypeBound) +
                      ", the most a channel's type holds (max_length: {" + at.path + ": N} bounds it tighter)");
      }
    } else {
      used_.insert(at.path);
      const std::uint32_t most = type.bound == 0 ? kMaxTypeBound : std::min(type.bound, kMaxTypeBound);
      if (given->second < 1 || given->second > most) {
        error(at,
              "max_length " + std::to_string(given->second) + " of " + at.path + " is not 1.." + std::to_string(most));
      } else {
        t.bound = given->second;
      }
    }
    if (t.kind == FieldType::Kind::sequence) {
      if (type.element.size() != 1) return std::nullopt;  // the reader gives a sequence one
      auto element = field_type(type.element[0], Place{at.owner, at.member, at.path + "[]"}, depth + 1);
      if (!element) return std::nullopt;
      t.element = {std::move(*element)};
    }
    return t;
  }

  std::optional<FieldType> nested(const IdlType& type, const Place& at, std::size_t depth) {
    const auto hit = structs_.find(type.name);
    if (hit == structs_.end()) return std::nullopt;  // the reader resolved it: not reached
    const IdlStruct& s = *hit->second;
    if (s.extensibility != top_.extensibility) {
      error(at, "struct " + s.name + " is " + extensibility_word(s.extensibility) + " but " + top_.name + " is " +
                    extensibility_word(top_.extensibility) +
                    ": a channel's CDR form gives every nested struct the extensibility of the whole");
      return std::nullopt;
    }
    FieldType t;
    t.kind = FieldType::Kind::record;
    t.fields = record(s, at.path, depth + 1);
    return t;
  }

  std::optional<FieldType> enumeration(const IdlType& type) const {
    const auto hit = enums_.find(type.name);
    if (hit == enums_.end()) return std::nullopt;
    FieldType t;
    t.kind = FieldType::Kind::enumeration;
    t.scalar = ScalarKind::int32;
    t.values = hit->second->values;
    return t;
  }

  // A typedef: its type with its own dimensions; the members' path and place stay the same.
  std::optional<FieldType> alias(const IdlType& type, const Place& at, std::size_t depth) {
    const auto hit = typedefs_.find(type.name);
    if (hit == typedefs_.end()) return std::nullopt;
    const IdlTypedef& t = *hit->second;
    // A typedef adds no level of its own, but counts against the depth so that chains stay short.
    return member_type(t.type, t.dimensions, at, depth + (t.dimensions.empty() ? 1 : 0));
  }

  const IdlStruct& top_;
  const std::map<std::string, std::uint32_t>& max_length_;
  IdlChannelType& out_;
  std::map<std::string, const IdlStruct*> structs_;
  std::map<std::string, const IdlEnum*> enums_;
  std::map<std::string, const IdlTypedef*> typedefs_;
  std::set<std::string> used_;
  std::size_t nodes_ = 0;
  bool failed_ = false;
};

// The member a check_type problem's place ("pose.x", "fields[2]", "ranges.element") starts at.
const IdlMember* member_at(const IdlStruct& s, const std::string& where) {
  const std::string first = where.substr(0, where.find_first_of(".["));
  const auto hit =
      std::find_if(s.members.begin(), s.members.end(), [&](const IdlMember& m) { return m.name == first; });
  return hit == s.members.end() ? nullptr : &*hit;
}

void report_type_problems(const IdlStruct& s, IdlChannelType& out) {
  for (const TypeProblem& p : check_type(out.type)) {
    // The usual cause: unbounded sequences count at kMaxTypeBound each.
    const bool too_big = p.what.find("scalars") != std::string::npos;
    const IdlMember* m = member_at(s, p.where);
    out.errors.push_back(
        IdlError{s.file, m ? m->line : s.line, m ? m->column : s.column,
                 s.name + ": " + (p.where.empty() ? "" : p.where + ": ") + p.what +
                     (too_big ? " (max_length: {MEMBER: N} bounds an unbounded sequence or string)" : "")});
  }
}

}  // namespace
}  // namespace idl_build

IdlChannelType idl_channel_type(const IdlTypeFile& file, const IdlStruct& s,
                                const std::map<std::string, std::uint32_t>& max_length) {
  IdlChannelType out;
  out.extensibility = s.extensibility;
  idl_build::TypeBuilder builder(file, s, max_length, out);
  out.type.fields = builder.record(s, "", 0);
  for (const std::string& path : builder.unused_max_length()) {
    out.errors.push_back(IdlError{s.file, s.line, s.column,
                                  "max_length names " + path + ", which is not a string or sequence of " + s.name});
  }
  if (out.errors.empty()) idl_build::report_type_problems(s, out);
  return out;
}

}  // namespace cosmic

// A ROS 2 message and the messages it refers to as a typed channel's contents
// (cosmic/msg_types.hpp): each message read once through the caller's loader (or the built-in
// definitions of builtin_interfaces), nested messages expanded where they are used, in the order
// and with the types of the IDL struct rosidl generates, so that its CDR form is what ROS 2 sends.
#include <algorithm>
#include <set>

#include "cosmic/msg_types.hpp"
#include "cosmic/units.hpp"

namespace cosmic {
// Named, then anonymous: unity builds merge this file with the other readers of cosmic_core.
namespace msg_resolve {
namespace {

// rcl_interfaces' builtin_interfaces/msg/Time.msg and Duration.msg, comments included.
constexpr std::string_view kTimeMsg =
    "# This message communicates ROS Time defined here:\n"
    "# https://design.ros2.org/articles/clock_and_time.html\n"
    "\n"
    "# The seconds component, valid over all int32 values.\n"
    "int32 sec\n"
    "\n"
    "# The nanoseconds component, valid in the range [0, 1e9), to be added to the seconds component.\n"
    "# e.g.\n"
    "# The time -1.7 seconds is represented as {sec: -2, nanosec: 3e8}\n"
    "# The time 1.7 seconds is represented as {sec: 1, nanosec: 7e8}\n"
    "uint32 nanosec\n";
constexpr std::string_view kDurationMsg =
    "# Duration defines a period between two time points.\n"
    "# Messages of this datatype are of ROS Time following this design:\n"
    "# https://design.ros2.org/articles/clock_and_time.html\n"
    "\n"
    "# The seconds component, valid over all int32 values.\n"
    "int32 sec\n"
    "\n"
    "# The nanoseconds component, valid in the range [0, 1e9), to be added to the seconds component.\n"
    "# e.g.\n"
    "# The duration -1.7 seconds is represented as {sec: -2, nanosec: 3e8}\n"
    "# The duration 1.7 seconds is represented as {sec: 1, nanosec: 7e8}\n"
    "uint32 nanosec\n";

// The member rosidl gives the struct of a message without fields (IDL has no empty struct).
constexpr std::string_view kPlaceholderField = "structure_needs_at_least_one_member";

ScalarKind primitive_kind(std::string_view name) {
  if (name == "bool") return ScalarKind::boolean;
  if (name == "byte" || name == "char") return ScalarKind::uint8;  // IDL octet and uint8: one byte each
  return scalar_kind(name).value_or(ScalarKind::uint8);            // int8..uint64, float32, float64
}

std::string child_path(const std::string& parent, const std::string& name) {
  return parent.empty() ? name : parent + "." + name;
}

// Where a field is written: its message and its line.
struct Site {
  const MsgTypeName* message = nullptr;  // none: the requested message itself, named by the caller
  const MsgField* field = nullptr;
};

class Resolver {
 public:
  Resolver(const MsgLoader& load, const std::map<std::string, std::uint32_t>& max_length, MsgChannelType& out)
      : load_(load), max_length_(max_length), out_(out) {}

  void run(const MsgTypeName& root) {
    root_ = root.full();
    const MsgFile* file = load(root, Site{});
    if (file == nullptr || !file->ok()) return;
    path_.push_back(root_);
    out_.type.fields = record(root, *file, "", 0);
    path_.pop_back();
    if (!out_.errors.empty()) return;
    unused_max_length();
    if (!out_.errors.empty()) return;
    for (const TypeProblem& p : check_type(out_.type)) {
      // The usual cause: unbounded sequences, each counted at kMaxTypeBound elements.
      const bool too_big = p.what.find("scalars") != std::string::npos;
      error(root_, 0, 0,
            (p.where.empty() ? "" : p.where + ": ") + p.what +
                (too_big ? " (max_length: {PATH: N} bounds an unbounded sequence)" : ""));
    }
  }

  void close() {
    if (unreported_ > 0)
      out_.errors.push_back(MsgTypeError{"", 0, 0, std::to_string(unreported_) + " more errors not reported"});
  }

 private:
  void error(const std::string& file, int line, int column, std::string message) {
    if (out_.errors.size() < kMaxReportedTextErrors) {
      out_.errors.push_back(MsgTypeError{file, line, column, std::move(message)});
    } else {
      ++unreported_;
    }
  }
  void error_at(const Site& site, std::string message) {
    if (site.message == nullptr) return error(root_, 0, 0, std::move(message));
    error(site.message->full(), site.field->line, site.field->column, std::move(message));
  }

  // The message's file, read and parsed once; nullptr when it cannot be read (reported at `site`).
  const MsgFile* load(const MsgTypeName& name, const Site& site) {
    const std::string key = name.full();
    if (const auto it = files_.find(key); it != files_.end()) {
      if (!it->second) error_at(site, not_found(name, site));
      return it->second ? &*it->second : nullptr;
    }
    if (files_.size() >= kMsgMaxFiles) {
      error_at(site, "more than " + std::to_string(kMsgMaxFiles) + " messages in one type");
      return nullptr;
    }
    std::optional<std::string> text = load_(name.package, name.name);
    bool built_in = false;
    if (!text) {
      const auto builtin = msg_builtin_text(name.package, name.name);
      if (builtin) text = std::string(*builtin);
      built_in = builtin.has_value();
    }
    if (!text) {
      files_[key] = std::nullopt;
      error_at(site, not_found(name, site));
      return nullptr;
    }
    out_.files.push_back(MsgSourceFile{key, built_in});
    auto& file = files_[key] = parse_msg(*text);
    for (const MsgError& e : file->errors) error(key, e.line, e.column, e.message);
    return &*file;
  }

  static std::string not_found(const MsgTypeName& name, const Site& site) {
    std::string message = name.full() + " not found on the type path";
    // ROS 1 read a bare Header as std_msgs/Header; rosidl reads it as a message of the same package.
    if (site.field != nullptr && site.field->type.package.empty() && name.name == "Header" &&
        name.package != "std_msgs") {
      message += " (a bare Header is " + name.package + "/Header in ROS 2: write std_msgs/Header)";
    }
    return message;
  }

  std::vector<TypeField> record(const MsgTypeName& owner, const MsgFile& file, const std::string& path,
                                std::size_t depth) {
    std::vector<TypeField> fields;
    if (file.fields.empty()) {
      FieldType placeholder;
      placeholder.scalar = ScalarKind::uint8;
      fields.push_back(TypeField{std::string(kPlaceholderField), placeholder, "", {}, {}, {}});
    }
    for (const MsgField& f : file.fields) {
      if (++fields_built_ > kMaxFlattenedScalars) {
        if (fields_built_ == kMaxFlattenedScalars + 1) {
          error(root_, 0, 0,
                "the type expands to more than " + std::to_string(kMaxFlattenedScalars) +
                    " fields (messages used many times over)");
        }
        return fields;
      }
      auto type = field_type(owner, f, child_path(path, f.name), depth);
      if (!type) continue;
      TypeField field{f.name, std::move(*type), "", {}, {}, {}};
      if (is_numeric(field.type)) field.unit = f.unit;  // a unit belongs to numbers only
      fields.push_back(std::move(field));
    }
    return fields;
  }

  // The field's type at `depth` (check_type's count: a record's fields and an array's element one
  // deeper), or nullopt with the reason reported.
  std::optional<FieldType> field_type(const MsgTypeName& owner, const MsgField& f, const std::string& path,
                                      std::size_t depth) {
    const bool array = f.type.array != MsgFieldType::Array::none;
    const std::size_t element_depth = depth + (array ? 1 : 0);
    const Site site{&owner, &f};
    if (element_depth >= kMaxTypeDepth || (!f.type.is_primitive() && element_depth + 1 >= kMaxTypeDepth)) {
      error_at(site, "field " + f.name + " is nested more than " + std::to_string(kMaxTypeDepth) +
                         " levels deep (messages and arrays)");
      return std::nullopt;
    }
    const std::string element_path = array ? path + "[]" : path;
    auto element =
        f.type.is_primitive() ? primitive(f, element_path, site) : message(owner, f, element_path, element_depth, site);
    if (!element || !array) return element;
    FieldType t;
    t.element = {std::move(*element)};
    t.kind = f.type.array == MsgFieldType::Array::fixed ? FieldType::Kind::array : FieldType::Kind::sequence;
    t.bound = f.type.array == MsgFieldType::Array::unbounded ? unbounded(path, site) : f.type.array_size;
    return t;
  }

  std::optional<FieldType> primitive(const MsgField& f, const std::string& path, const Site& site) {
    FieldType t;
    if (f.type.name != "string") {
      t.scalar = primitive_kind(f.type.name);
      return t;
    }
    t.kind = FieldType::Kind::string;
    t.bound = f.type.string_bound != 0 ? f.type.string_bound : unbounded(path, site);
    return t;
  }

  std::optional<FieldType> message(const MsgTypeName& owner, const MsgField& f, const std::string& path,
                                   std::size_t depth, const Site& site) {
    const MsgTypeName name{f.type.package.empty() ? owner.package : f.type.package, f.type.name};
    const std::string key = name.full();
    if (std::find(path_.begin(), path_.end(), key) != path_.end()) {
      std::string chain;
      for (auto it = std::find(path_.begin(), path_.end(), key); it != path_.end(); ++it) chain += *it + " -> ";
      error_at(site, "a message cannot contain itself: " + chain + key);
      return std::nullopt;
    }
    const MsgFile* file = load(name, site);
    if (file == nullptr || !file->ok()) return std::nullopt;  // the file's own errors are reported in it
    path_.push_back(key);
    FieldType t;
    t.kind = FieldType::Kind::record;
    t.fields = record(name, *file, path, depth + 1);
    path_.pop_back();
    return t;
  }

  // An unbounded string's or sequence's bound: max_length's for its path, else kMaxTypeBound.
  std::uint32_t unbounded(const std::string& path, const Site& site) {
    const auto given = max_length_.find(path);
    if (given == max_length_.end()) return kMaxTypeBound;
    used_.insert(path);
    if (given->second < 1 || given->second > kMaxTypeBound) {
      error_at(site, "max_length " + std::to_string(given->second) + " of " + path + " is not 1.." +
                         std::to_string(kMaxTypeBound));
      return kMaxTypeBound;
    }
    return given->second;
  }

  void unused_max_length() {
    for (const auto& entry : max_length_) {
      if (used_.count(entry.first) != 0) continue;
      error(root_, 0, 0,
            "max_length names " + quote_value(entry.first) + ", which is not an unbounded string or sequence of " +
                root_ + " (a path: field names joined by '.', \"[]\" to step into an array's elements)");
    }
  }

  const MsgLoader& load_;
  const std::map<std::string, std::uint32_t>& max_length_;
  MsgChannelType& out_;
  std::string root_;
  std::map<std::string, std::optional<MsgFile>> files_;  // by full name; nullopt: not found
  std::vector<std::string> path_;                        // the messages being expanded, outermost first
  std::set<std::string> used_;                           // max_length's paths that bounded something
  std::size_t fields_built_ = 0;
  std::size_t unreported_ = 0;
};

}  // namespace
}  // namespace msg_resolve

std::optional<std::string_view> msg_builtin_text(std::string_view package, std::string_view name) {
  if (package != "builtin_interfaces") return std::nullopt;
  if (name == "Time") return msg_resolve::kTimeMsg;
  if (name == "Duration") return msg_resolve::kDurationMsg;
  return std::nullopt;
}

MsgChannelType msg_channel_type(const std::string& package, const std::string& name, const MsgLoader& load,
                                const std::map<std::string, std::uint32_t>& max_length) {
  MsgChannelType out;
  const auto root = msg_type_name(package + "/" + name);
  if (!root || root->package != package || root->name != name) {
    out.errors.push_back(MsgTypeError{package + "/msg/" + name, 0, 0,
                                      "not a ROS 2 message name: package [a-z][a-z0-9_]*, message [A-Z][A-Za-z0-9]*"});
    return out;
  }
  msg_resolve::Resolver resolver(load, max_length, out);
  resolver.run(*root);
  resolver.close();
  return out;
}

}  // namespace cosmic

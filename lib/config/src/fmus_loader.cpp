// The `fmus:` section (fmus_loader.hpp).
#include "fmus_loader.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "cosmic/fmi_mapping.hpp"
#include "cosmic/fmu_channel_fields.hpp"
#include "cosmic/fmu_archive.hpp"
#include "cosmic/units.hpp"

namespace cosmic::config_detail {
namespace {

constexpr std::size_t kListedNames = 12;  // names a "one of ..." hint shows at most

std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < kListedNames; ++i) out += (i == 0 ? "" : ", ") + names[i];
  if (names.size() > kListedNames) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out.empty() ? "(none)" : out;
}

// The always-present fields an event needs, as dotted paths: records are entered; conditional
// fields (a DBC multiplexed signal) are left out.
void leaves(const std::vector<TypeField>& fields, const std::string& prefix, std::vector<std::string>& out) {
  for (const TypeField& f : fields) {
    if (f.present_when) continue;
    if (f.type.kind == FieldType::Kind::record) {
      leaves(f.type.fields, prefix + f.name + ".", out);
    } else {
      out.push_back(prefix + f.name);
    }
  }
}

std::vector<std::string> names_with(const fmi::FmuDescription& d, fmi::Causality causality) {
  std::vector<std::string> out;
  for (const auto& v : d.variables)
    if (v.causality == causality) out.push_back(v.name);
  return out;
}

// Component names the document declares, so an FMU cannot take one.
std::set<std::string> component_names(const YAML::Node& root) {
  std::set<std::string> out;
  const YAML::Node list = root["components"];
  if (!list || !list.IsSequence()) return out;
  for (const auto& c : list)
    if (c.IsMap() && c["name"] && c["name"].IsScalar()) out.insert(c["name"].Scalar());
  return out;
}

class FmusLoader {
 public:
  FmusLoader(YamlReader& reader, const YAML::Node& root, Config& config, std::vector<std::string>& included)
      : reader_(reader), root_(root), config_(config), included_(included), components_(component_names(root)) {
    const YAML::Node channels = root["channels"];
    if (channels && channels.IsSequence())
      for (const auto& c : channels)
        if (c.IsMap() && c["name"] && c["name"].IsScalar()) channel_nodes_.insert(c["name"].Scalar());
  }

  void run() {
    if (!has(root_, "fmus") || !reader_.is_list(root_["fmus"], "fmus")) return;
    const YAML::Node list = root_["fmus"];
    for (std::size_t i = 0; i < list.size(); ++i) read_entry(list[i], indexed("fmus", i));
  }

 private:
  void read_entry(const YAML::Node& node, const std::string& path) {
    if (!reader_.check_map(node, path, {"name", "fmu", "segment", "step", "inputs", "outputs", "parameters"})) return;
    const std::size_t errors_before = reader_.error_count();
    FmuSpec f;
    if (reader_.require(node, path, "name", "a name for the FMU component"))
      f.name = reader_.name(node["name"], key(path, "name")).value_or("");
    if (reader_.require(node, path, "segment", "the segment the FMU's runner lives on")) read_segment(node, path, f);
    std::optional<fmi::FmuDescription> description;
    if (reader_.require(node, path, "fmu", "the FMU file (relative to this configuration)"))
      description = read_fmu_file(node, path, f);
    read_step(node, path, description ? &*description : nullptr, f);
    const fmi::FmuDescription* d = description ? &*description : nullptr;
    read_mappings(node, path, "inputs", fmi::Flow::input, d, f.inputs);
    const std::size_t errors_before_outputs = reader_.error_count();
    read_mappings(node, path, "outputs", fmi::Flow::output, d, f.outputs);
    // Fields whose output was refused are not missing on top of it.
    if (reader_.error_count() == errors_before_outputs) check_outputs_complete(node, path, f);
    read_parameters(node, path, d, f);
    if (reader_.error_count() != errors_before) return;
    check_step_against_periods(node, path, f);
    if (reader_.error_count() != errors_before) return;
    if (components_.count(f.name) || !names_.insert(f.name).second) {
      reader_.error_at(node["name"], key(path, "name"), "name '" + f.name + "' is taken",
                       "a name not used by a component or another FMU");
      return;
    }
    config_.fmus.push_back(std::move(f));
    add_fmu_publishers(std::span(&config_.fmus.back(), 1), config_.channels);
  }

  // The FMU publishes each output channel once per step: a step shorter than a channel's period
  // would send more than admission granted, and rate policing would drop the excess.
  void check_step_against_periods(const YAML::Node& node, const std::string& path, const FmuSpec& f) {
    const bool written = has(node, "step");
    for (const auto& name : f.publishes()) {
      const ChannelSpec* channel = config_.find_channel(name);
      if (!channel->period || f.step >= *channel->period) continue;
      const std::string step = written ? node["step"].Scalar() : "no step given: the FMU's DefaultExperiment stepSize";
      reader_.error_at(written ? node["step"] : node, key(path, "step"),
                       step + " publishes '" + name + "' every " + format_duration(f.step) +
                           ", faster than its period " + format_duration(*channel->period),
                       "a step at least the period of every output channel");
    }
  }

  void read_segment(const YAML::Node& node, const std::string& path, FmuSpec& f) {
    const auto name = reader_.string(node["segment"], key(path, "segment"));
    if (!name) return;
    const SegmentSpec* segment = config_.find_segment(*name);
    if (segment == nullptr || segment->type == SegmentType::replay) {
      std::vector<std::string> known;
      for (const auto& s : config_.segments)
        if (s.type != SegmentType::replay) known.push_back(s.name);
      reader_.error_at(node["segment"], key(path, "segment"),
                       segment == nullptr ? "unknown segment '" + *name + "'"
                                          : "segment '" + *name + "' is a replay: no component lives there",
                       "one of the CAN, DDS and LCM segments: " + listed(known));
      return;
    }
    f.segment = *name;
  }

  std::optional<fmi::FmuDescription> read_fmu_file(const YAML::Node& node, const std::string& path, FmuSpec& f) {
    const auto text = reader_.string(node["fmu"], key(path, "fmu"));
    if (!text) return std::nullopt;
    const std::filesystem::path given(*text);
    f.fmu = given.is_absolute()
                ? given.lexically_normal().string()
                : (std::filesystem::absolute(reader_.file()).parent_path() / given).lexically_normal().string();
    included_.push_back(f.fmu);
    fmi::FmuReadResult read = fmi::read_fmu(f.fmu);
    for (const auto& e : read.errors)
      reader_.error_at(node["fmu"], key(path, "fmu"), e,
                       "a co-simulation FMU (FMI 2.0 or 3.x) with a binary for this platform");
    if (!read.ok()) return std::nullopt;
    f.fmi_version = read.contents.description.fmi_version;
    f.model_identifier = read.contents.description.co_simulation->model_identifier;
    return std::move(read.contents.description);
  }

  void read_step(const YAML::Node& node, const std::string& path, const fmi::FmuDescription* d, FmuSpec& f) {
    if (has(node, "step")) {
      if (auto step = reader_.duration(node["step"], key(path, "step"), false)) f.step = *step;
      return;
    }
    if (node["step"]) return;  // a key without a value: check_map's to report
    const std::optional<double> seconds = d != nullptr ? d->default_experiment.step_size : std::nullopt;
    if (seconds && std::llround(*seconds * 1e9) >= 1) {
      f.step = Nanos(std::llround(*seconds * 1e9));
    } else if (d != nullptr) {
      reader_.error_at(node, key(path, "step"), "missing required key 'step'",
                       "the communication step, such as 10ms (the FMU's DefaultExperiment gives no stepSize)");
    }
  }

  // Calls entry(key node, value node, variable, entry path, value text) for each entry of the map
  // `role` whose variable name and value are strings, each variable once.
  template <typename Entry>
  void each_entry(const YAML::Node& node, const std::string& path, const char* role, const char* valid, Entry&& entry) {
    if (!has(node, role)) return;
    const std::string p = key(path, role);
    const YAML::Node map = node[role];
    if (!map.IsMap()) {
      reader_.error_at(map, p, std::string(role) + " is not a map", valid);
      return;
    }
    std::set<std::string> seen;
    for (auto it = map.begin(); it != map.end(); ++it) {
      const auto variable = reader_.string(it->first, p);
      if (!variable) continue;
      const std::string at = p + "." + *variable;
      if (!seen.insert(*variable).second) {
        reader_.error_at(it->first, at, "variable '" + *variable + "' given twice", "each variable once");
        continue;
      }
      if (const auto value = reader_.string(it->second, at)) entry(it->first, it->second, *variable, at, *value);
    }
  }

  void read_mappings(const YAML::Node& node, const std::string& path, const char* role, fmi::Flow flow,
                     const fmi::FmuDescription* d, std::vector<FmuVariableMapping>& out) {
    each_entry(node, path, role, "VARIABLE: channel.field entries",
               [&](const YAML::Node& name, const YAML::Node& value, const std::string& variable, const std::string& at,
                   const std::string& target) {
                 FmuVariableMapping m{variable, {}, {}};
                 const TypeField* field = read_target(value, at, target, m);
                 if (field == nullptr) return;
                 if (flow == fmi::Flow::output && field->present_when) {
                   reader_.error_at(value, at, "field '" + m.field + "' of '" + m.channel + "' is conditional",
                                    "an always-present field (the FMU sets its selector's value in no way the "
                                    "gateway knows)");
                   return;
                 }
                 if (d != nullptr && !check_variable(name, at, *d, m, *field, flow)) return;
                 out.push_back(std::move(m));
               });
  }

  // The channel field `target` (channel.field) names, or null after saying why not.
  const TypeField* read_target(const YAML::Node& at, const std::string& path, const std::string& target,
                               FmuVariableMapping& m) {
    const std::size_t dot = target.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == target.size()) {
      reader_.error_at(at, path, "'" + target + "' is not channel.field", "a typed channel's name, a dot, a field");
      return nullptr;
    }
    m.channel = target.substr(0, dot);
    m.field = target.substr(dot + 1);
    const ChannelSpec* channel = config_.find_channel(m.channel);
    if (channel == nullptr) {
      if (channel_nodes_.count(m.channel)) return nullptr;  // a channel with errors of its own
      std::vector<std::string> typed;
      for (const auto& c : config_.channels)
        if (c.type) typed.push_back(c.name);
      reader_.error_at(at, path, "unknown channel '" + m.channel + "'", "one of the typed channels: " + listed(typed));
      return nullptr;
    }
    if (!channel->type) {
      reader_.error_at(at, path, "channel '" + m.channel + "' has no type",
                       "a channel with a type (yaml-reference.md, `type`): an FMU variable maps to one of its fields");
      return nullptr;
    }
    const TypeField* field = fmi::field_at_path(channel->type->fields, m.field);
    if (field == nullptr) {
      std::vector<std::string> fields;
      leaves(channel->type->fields, "", fields);
      reader_.error_at(at, path, "channel '" + m.channel + "' has no field '" + m.field + "'",
                       "one of its fields: " + listed(fields));
    }
    return field;
  }

  bool check_variable(const YAML::Node& at, const std::string& path, const fmi::FmuDescription& d,
                      const FmuVariableMapping& m, const TypeField& field, fmi::Flow flow) {
    const fmi::Causality wanted = flow == fmi::Flow::input ? fmi::Causality::input : fmi::Causality::output;
    const std::string kind = flow == fmi::Flow::input ? "input" : "output";
    const fmi::Variable* v = d.find_variable(m.variable);
    if (v == nullptr || v->causality != wanted) {
      reader_.error_at(at, path,
                       v == nullptr ? "the FMU has no variable '" + m.variable + "'"
                                    : "variable '" + m.variable + "' is " + std::string(fmi::to_string(v->causality)) +
                                          ", not " + kind,
                       "one of the FMU's " + kind + "s: " + listed(names_with(d, wanted)));
      return false;
    }
    if (auto why = fmi::mapping_problem(*v, d, field, flow); !why.empty()) {
      reader_.error_at(at, path,
                       std::string(fmi::type_element(v->type, d.version)) + " variable '" + m.variable +
                           "' cannot carry " + m.channel + "." + m.field + " (" + describe(field.type) + "): " + why,
                       "a variable and field of the mapping table (docs/fmu.md)");
      return false;
    }
    return true;
  }

  // An FMU publishes whole events: every always-present field of an output channel set by one output.
  void check_outputs_complete(const YAML::Node& node, const std::string& path, const FmuSpec& f) {
    std::map<std::string, std::string> set_by;  // channel.field -> variable
    for (const auto& m : f.outputs) {
      const std::string target = m.channel + "." + m.field;
      if (const auto [it, fresh] = set_by.emplace(target, m.variable); !fresh) {
        reader_.error_at(node["outputs"][m.variable], key(path, "outputs") + "." + m.variable,
                         target + " is set by '" + it->second + "' already", "one output per field");
      }
    }
    for (const auto& channel : f.publishes()) {
      std::vector<std::string> fields;
      leaves(config_.find_channel(channel)->type->fields, "", fields);
      std::vector<std::string> unset;
      for (const auto& field : fields)
        if (!set_by.count(channel + "." + field)) unset.push_back(field);
      if (!unset.empty()) {
        reader_.error_at(node["outputs"], key(path, "outputs"),
                         "the outputs set fields of '" + channel + "' but not " + listed(unset),
                         "an output for every field of '" + channel + "': the FMU publishes whole events");
      }
    }
  }

  void read_parameters(const YAML::Node& node, const std::string& path, const fmi::FmuDescription* d, FmuSpec& f) {
    each_entry(node, path, "parameters", "VARIABLE: value entries",
               [&](const YAML::Node& name, const YAML::Node& value_node, const std::string& variable,
                   const std::string& at, const std::string& value) {
                 if (d != nullptr && !check_parameter(name, value_node, at, *d, variable, value)) return;
                 f.parameters.push_back({variable, value});
               });
  }

  bool check_parameter(const YAML::Node& name_node, const YAML::Node& value_node, const std::string& path,
                       const fmi::FmuDescription& d, const std::string& name, const std::string& value) {
    const fmi::Variable* v = d.find_variable(name);
    const bool settable = v != nullptr && v->causality == fmi::Causality::parameter &&
                          (v->variability == fmi::Variability::fixed || v->variability == fmi::Variability::tunable);
    if (!settable) {
      std::vector<std::string> parameters;
      for (const auto& candidate : d.variables)
        if (candidate.causality == fmi::Causality::parameter && candidate.variability != fmi::Variability::constant)
          parameters.push_back(candidate.name);
      reader_.error_at(name_node, path,
                       v == nullptr ? "the FMU has no variable '" + name + "'"
                                    : "variable '" + name + "' is " + std::string(fmi::to_string(v->causality)) + ", " +
                                          std::string(fmi::to_string(v->variability)) +
                                          ": only a fixed or tunable parameter is set",
                       "one of the FMU's parameters: " + listed(parameters));
      return false;
    }
    if (auto why = fmi::parameter_problem(*v, d, value); !why.empty()) {
      reader_.error_at(value_node, path, why,
                       "a value of the parameter's type (" + std::string(fmi::type_element(v->type, d.version)) + ")");
      return false;
    }
    return true;
  }

  YamlReader& reader_;
  const YAML::Node& root_;
  Config& config_;
  std::vector<std::string>& included_;
  std::set<std::string> components_;
  std::set<std::string> channel_nodes_;
  std::set<std::string> names_;
};

}  // namespace

void load_fmus(YamlReader& reader, const YAML::Node& root, Config& config, std::vector<std::string>& included) {
  FmusLoader(reader, root, config, included).run();
}

void add_fmu_publishers(std::span<const FmuSpec> fmus, std::vector<ChannelSpec>& channels) {
  for (const FmuSpec& f : fmus) {
    for (const auto& name : f.publishes()) {
      for (ChannelSpec& channel : channels)
        if (channel.name == name) channel.fmu_publishers.push_back({f.name, f.segment, f.step});
    }
  }
}

}  // namespace cosmic::config_detail

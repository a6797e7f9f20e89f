// The channel model from the gateway's own YAML loader, durations in the gateway's units, and the
// control query of a running cosmicd.
#include <pybind11/stl.h>

#include "binding.hpp"
#include "cosmic/channel_type.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/units.hpp"

namespace cosmic::python {
namespace {

py::object nanos_or_none(const std::optional<Nanos>& value) {
  if (!value) return py::none();
  return py::int_(value->count());
}

py::object number_or_none(const std::optional<double>& value) {
  if (!value) return py::none();
  return py::float_(*value);
}

py::list fields_desc(const std::vector<TypeField>& fields);

// A field's type as cosmic._typed reads it: {"kind", "scalar", "bound", "values", "element", "fields"}.
py::dict field_type_desc(const FieldType& type) {
  static constexpr const char* kKinds[] = {"scalar", "enum", "string", "array", "sequence", "record"};
  FieldType scalar;
  scalar.scalar = type.scalar;
  py::dict values;
  for (const EnumValue& v : type.values) values[py::str(v.name)] = v.value;
  py::dict d;
  d["kind"] = kKinds[static_cast<std::size_t>(type.kind)];
  d["scalar"] = describe(scalar);  // "float64", "uint8", ...: also an enumeration's integer
  d["bound"] = type.bound;
  d["values"] = values;
  d["element"] = type.element.empty() ? py::object(py::none()) : py::object(field_type_desc(type.element.front()));
  d["fields"] = fields_desc(type.fields);
  return d;
}

py::list fields_desc(const std::vector<TypeField>& fields) {
  py::list out;
  for (const TypeField& f : fields) {
    py::dict d;
    d["name"] = f.name;
    d["type"] = field_type_desc(f.type);
    d["unit"] = f.unit;
    d["min"] = number_or_none(f.minimum);
    d["max"] = number_or_none(f.maximum);
    d["present_when"] = f.present_when ? py::object(py::make_tuple(f.present_when->selector, f.present_when->value))
                                       : py::object(py::none());
    out.append(d);
  }
  return out;
}

// One channel of a gateway configuration, as cosmicd reads it (parse_config: the whole file is
// validated, errors located as `cosmicctl check` prints them). Durations in nanoseconds.
py::dict load_channel(const std::string& path, const std::string& name) {
  ConfigResult result;
  {
    py::gil_scoped_release nogil;
    result = load_config_file(path);
  }
  if (!result.ok()) {
    std::string message = path + " has " + std::to_string(result.errors.size()) + " error(s):";
    for (const auto& error : result.errors) message += "\n  " + error.to_string();
    raise_error(COSMIC_E_INVALID, message);
  }
  const ChannelSpec* spec = result.config.find_channel(name);
  if (!spec) {
    std::string names;
    for (const auto& channel : result.config.channels) names += (names.empty() ? "" : ", ") + channel.name;
    raise_error(COSMIC_E_INVALID, "no channel '" + name + "' in " + path + " (channels: " + names + ")");
  }
  if (spec->payload > UINT32_MAX) raise_error(COSMIC_E_INVALID, "channel '" + name + "': payload larger than 4 GiB");
  static constexpr const char* kClasses[] = {"hrt", "srt", "nrt"};
  py::dict d;
  d["name"] = spec->name;
  d["subject"] = spec->subject;
  d["cls"] = kClasses[static_cast<int>(spec->cls)];
  d["period_ns"] = nanos_or_none(spec->period);
  d["reaction_time_ns"] = nanos_or_none(spec->reaction_time);
  d["temp_validity_ns"] = nanos_or_none(spec->temp_validity);
  d["omission_degree"] = spec->omission_degree;
  d["payload"] = spec->payload;
  // A typed channel's fields (cosmic._typed.ChannelType reads them); None: opaque bytes.
  d["type"] = spec->type ? py::object(fields_desc(spec->type->fields)) : py::object(py::none());
  return d;
}

std::int64_t parse_duration_ns(const std::string& text) {
  const auto parsed = cosmic::parse_duration(text);
  if (!parsed.value) raise_error(COSMIC_E_INVALID, parsed.error);
  return parsed.value->count();
}

std::string check_channel(const std::string& socket, const std::string& name) {
  char verdict[1024] = "";
  int rc = COSMIC_OK;
  {
    py::gil_scoped_release nogil;  // up to 5 s for an answer
    rc = cosmic_check_channel(socket.c_str(), name.c_str(), verdict, sizeof verdict);
  }
  if (rc != COSMIC_OK) raise_error(rc, "check_channel('" + name + "') at " + socket + ": " + verdict);
  if (std::string(verdict) == "not_found") {
    raise_error(COSMIC_E_UNBOUND,
                "check_channel('" + name + "') at " + socket + ": the gateway does not know the channel (not_found)");
  }
  return verdict;
}

}  // namespace

void bind_model(py::module_& m) {
  using namespace py::literals;
  m.def("_load_channel", &load_channel, "path"_a, "name"_a,
        "One channel of a gateway configuration through cosmicd's own loader, as a dict (durations in ns).");
  m.def("parse_duration_ns", &parse_duration_ns, "text"_a,
        "A duration as the YAML writes it ('10ms', '250us', '1.5s') in nanoseconds; cosmic.InvalidError otherwise.");
  m.def("check_channel", &check_channel, "socket"_a, "name"_a, R"doc(
Asks the cosmicd listening on the control socket `socket` for the verdict of channel `name`:
"bound", "degraded", "violated", "failed", or "rejected (REASONS)" for a channel of its
configuration that admission rejected. Raises cosmic.UnboundError when the gateway does not know
the channel and cosmic.UnavailableError when it cannot be asked. The GIL is released meanwhile.)doc");
}

}  // namespace cosmic::python

// The get-event step of an FMU (cosmic/fmu_stepper.hpp).
#include "cosmic/fmu_stepper.hpp"

#include <map>

namespace cosmic::fmi {

void InputLatch::offer(std::span<const std::uint8_t> event) {
  LockGuard lock(mutex_);
  pending_.assign(event.begin(), event.end());
  ++arrived_;
}

bool InputLatch::take(std::vector<std::uint8_t>& event, std::uint64_t& arrived) {
  LockGuard lock(mutex_);
  arrived = arrived_;
  if (arrived_ == 0) return false;
  event.swap(pending_);
  arrived_ = 0;
  return true;
}

namespace {

// A channel's mapped fields grouped: channel -> (field paths, variables), in the order first mapped.
struct Grouped {
  std::vector<std::string> channels;
  std::map<std::string, std::pair<std::vector<std::string>, std::vector<const Variable*>>> by_channel;
};

Result<Grouped> group(const std::vector<FmuVariableMapping>& mappings, const FmuDescription& description) {
  Grouped out;
  for (const auto& m : mappings) {
    const Variable* v = description.find_variable(m.variable);
    if (v == nullptr) return Error{"the FMU has no variable '" + m.variable + "'"};
    auto [it, fresh] = out.by_channel.try_emplace(m.channel);
    if (fresh) out.channels.push_back(m.channel);
    it->second.first.push_back(m.field);
    it->second.second.push_back(v);
  }
  return out;
}

Result<ChannelFields> fields_of(const Config& config, const std::string& channel,
                                const std::vector<std::string>& paths) {
  const ChannelSpec* spec = config.find_channel(channel);
  if (spec == nullptr || !spec->type) return Error{"'" + channel + "' is no typed channel of the configuration"};
  auto fields = ChannelFields::make(*spec->type, paths);
  if (!fields) return Error{"channel '" + channel + "': " + fields.error().text};
  return fields;
}

}  // namespace

Result<std::unique_ptr<FmuStepper>> FmuStepper::make(const FmuSpec& spec, const FmuDescription& description,
                                                     const Config& config, FmuInstance& instance) {
  if (spec.step.count() <= 0) return Error{"the step is not positive"};
  std::unique_ptr<FmuStepper> out(new FmuStepper(spec, description, instance));
  auto inputs = group(spec.inputs, description);
  if (!inputs) return inputs.error();
  for (const auto& channel : inputs.value().channels) {
    const auto& [paths, variables] = inputs.value().by_channel.at(channel);
    auto fields = fields_of(config, channel, paths);
    if (!fields) return fields.error();
    out->inputs_.push_back(Input{
        channel, std::make_unique<InputLatch>(), std::move(fields.value()), variables, {}, {}, InputCounters{channel}});
  }
  auto outputs = group(spec.outputs, description);
  if (!outputs) return outputs.error();
  for (const auto& channel : outputs.value().channels) {
    const auto& [paths, variables] = outputs.value().by_channel.at(channel);
    auto fields = fields_of(config, channel, paths);
    if (!fields) return fields.error();
    out->outputs_.push_back(Output{channel, std::move(fields.value()), variables, {}, {}, OutputCounters{channel}});
  }
  return out;
}

Result<void> FmuStepper::start() {
  for (const auto& p : spec_.parameters) {
    const Variable* v = description_.find_variable(p.variable);
    if (v == nullptr) return Error{"the FMU has no parameter '" + p.variable + "'"};
    auto value = parse_value(*v, description_, p.value);
    if (!value) return Error{"parameter '" + p.variable + "': " + value.error().text};
    if (auto set = instance_.set(*v, value.value()); !set) return set;
  }
  return instance_.initialize(0.0);
}

Result<void> FmuStepper::step(std::uint64_t index) {
  if (auto in = take_inputs(); !in) return in;
  const double time = static_cast<double>(index) * step_seconds_;
  if (auto stepped = instance_.do_step(time, step_seconds_); !stepped) return stepped;
  return make_outputs();
}

Result<void> FmuStepper::take_inputs() {
  for (Input& in : inputs_) {
    std::uint64_t arrived = 0;
    if (!in.latch->take(in.event, arrived)) continue;
    in.counters.skipped += arrived - 1;
    if (!in.fields.read(in.event, in.values)) {
      ++in.counters.decode_errors;  // the variables keep the last good event's values
      continue;
    }
    ++in.counters.taken;
    bool undecodable = false;
    for (std::size_t slot = 0; slot < in.variables.size(); ++slot) {
      if (!in.values[slot].present) continue;  // a conditional field not selected: the variable keeps its value
      const Variable& v = *in.variables[slot];
      bool clipped = false;
      const auto value = to_variable(v, description_, in.fields.field(slot), in.values[slot], clipped);
      if (!value) {
        undecodable = true;  // an enumeration value that is none of the variable's items
        continue;
      }
      if (clipped) ++in.counters.clipped;
      if (auto set = instance_.set(v, *value); !set) return set;
    }
    if (undecodable) ++in.counters.decode_errors;
  }
  return {};
}

Result<void> FmuStepper::make_outputs() {
  for (Output& out : outputs_) {
    out.values.resize(out.variables.size());
    for (std::size_t slot = 0; slot < out.variables.size(); ++slot) {
      auto value = instance_.get(*out.variables[slot]);
      if (!value) return value.error();
      bool clipped = false;
      out.values[slot] = to_field(out.fields.field(slot), value.value(), clipped);
      if (clipped) ++out.counters.clipped;
    }
    out.fields.write(out.values, out.event);
    ++out.counters.events;
  }
  return {};
}

std::vector<InputCounters> FmuStepper::input_counters() const {
  std::vector<InputCounters> out;
  for (const auto& in : inputs_) out.push_back(in.counters);
  return out;
}

std::vector<OutputCounters> FmuStepper::output_counters() const {
  std::vector<OutputCounters> out;
  for (const auto& o : outputs_) out.push_back(o.counters);
  return out;
}

void FmuStepper::copy_counters(std::vector<InputCounters>& inputs, std::vector<OutputCounters>& outputs) const {
  if (inputs.size() != inputs_.size()) inputs = input_counters();
  if (outputs.size() != outputs_.size()) outputs = output_counters();
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    const InputCounters& c = inputs_[i].counters;
    inputs[i].taken = c.taken;
    inputs[i].skipped = c.skipped;
    inputs[i].decode_errors = c.decode_errors;
    inputs[i].clipped = c.clipped;
  }
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    outputs[i].events = outputs_[i].counters.events;
    outputs[i].clipped = outputs_[i].counters.clipped;
  }
}

}  // namespace cosmic::fmi

// The runner's engine without a network (docs/fmu.md "Stepping"): mapped fields in and out of
// compact events, values converted by the mapping table, and the get-event step (the newest event
// of each input before the step, the skipped ones counted) driven against a scripted FMU instance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <thread>

#include "cosmic/compact_layout.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/fmu_channel_fields.hpp"
#include "cosmic/fmu_stepper.hpp"

namespace cosmic::fmi {
namespace {

// An event of {pose: {v: float64, n: uint8}, label: string(8), samples: sequence<float32, 4>, ready: bool}.
ChannelType state_type() {
  ConfigResult loaded = parse_config(
      "segments:\n"
      "  - {name: lan, type: dds, domain: 0}\n"
      "  - {name: viz, type: lcm}\n"
      "channels:\n"
      "  - name: state\n"
      "    subject: 0x11\n"
      "    class: nrt\n"
      "    publishers: [lan]\n"
      "    subscribers: [viz]\n"
      "    type: {fields: [{name: pose, type: record, fields: [{name: v, type: float64}, {name: n, type: uint8}]},\n"
      "            {name: label, type: string, max_length: 8}, {name: samples, type: sequence, max_length: 4,\n"
      "            element: float32}, {name: ready, type: bool}]}\n",
      "state.yaml");
  EXPECT_TRUE(loaded.errors.empty()) << (loaded.errors.empty() ? "" : loaded.errors.front().to_string());
  return loaded.errors.empty() ? *loaded.config.channels.at(0).type : ChannelType{};
}

template <typename T>
void append(std::vector<std::uint8_t>& out, T value) {
  const std::size_t at = out.size();
  out.resize(at + sizeof value);
  std::memcpy(out.data() + at, &value, sizeof value);
}

std::vector<std::uint8_t> state_event(double v, std::uint8_t n, const std::string& label, std::uint32_t samples,
                                      bool ready) {
  std::vector<std::uint8_t> e;
  append(e, v);
  append(e, n);
  append(e, static_cast<std::uint32_t>(label.size()));
  e.insert(e.end(), label.begin(), label.end());
  append(e, samples);
  for (std::uint32_t i = 0; i < samples; ++i) append(e, 0.5f * static_cast<float>(i));
  append(e, static_cast<std::uint8_t>(ready));
  return e;
}

TEST(ChannelFields, ReadsMappedFieldsPastStringsAndSequences) {
  const ChannelType type = state_type();
  auto fields = ChannelFields::make(type, {"ready", "pose.v", "label"});
  ASSERT_TRUE(fields) << fields.error().text;
  std::vector<FieldValue> slots;
  ASSERT_TRUE(fields.value().read(state_event(2.5, 7, "ab", 3, true), slots));
  EXPECT_EQ(slots[0].scalar.unsigned_integer, 1u);
  EXPECT_EQ(slots[1].scalar.real, 2.5);
  EXPECT_EQ(slots[2].text, "ab");
  // Not one event of the type: refused with the reason, the slots untouched.
  auto bad = state_event(2.5, 7, "ab", 3, true);
  bad.pop_back();
  EXPECT_FALSE(fields.value().read(bad, slots));
}

TEST(ChannelFields, RefusesPathsThatNameNoScalarOrString) {
  const ChannelType type = state_type();
  EXPECT_FALSE(ChannelFields::make(type, {"pose"}));
  EXPECT_FALSE(ChannelFields::make(type, {"samples"}));
  EXPECT_FALSE(ChannelFields::make(type, {"pose.w"}));
}

TEST(ChannelFields, WritesAWholeEventWithUnmappedFieldsZero) {
  const ChannelType type = state_type();
  auto fields = ChannelFields::make(type, {"pose.v", "pose.n", "label", "ready"});
  ASSERT_TRUE(fields);
  std::vector<FieldValue> slots(4);
  slots[0].scalar.real = -1.25;
  slots[1].scalar.unsigned_integer = 200;
  slots[2].text = "a label longer than eight";
  slots[3].scalar.unsigned_integer = 1;
  std::vector<std::uint8_t> event;
  fields.value().write(slots, event);
  EXPECT_EQ(event, state_event(-1.25, 200, "a label ", 0, true));
  EXPECT_TRUE(check_compact(type, event));
}

FmuDescription description_of(FmiVersion version) {
  FmuDescription d;
  d.version = version;
  return d;
}

Variable variable(VariableType type) {
  Variable v;
  v.name = "x";
  v.type = type;
  return v;
}

TypeField bounded_field(ScalarKind kind, std::optional<double> min = {}, std::optional<double> max = {}) {
  TypeField f;
  f.name = "f";
  f.type.scalar = kind;
  f.minimum = min;
  f.maximum = max;
  return f;
}

TEST(FmiValues, AFloatIntoAnIntegerFieldIsRoundedAndSaturatedWithTheClipCounted) {
  bool clipped = false;
  EXPECT_EQ(to_field(bounded_field(ScalarKind::int16), 2.5, clipped).scalar.integer, 2);  // to nearest even
  EXPECT_EQ(to_field(bounded_field(ScalarKind::int16), -3.6, clipped).scalar.integer, -4);
  EXPECT_FALSE(clipped);
  EXPECT_EQ(to_field(bounded_field(ScalarKind::int16), 1e9, clipped).scalar.integer, 32767);
  EXPECT_TRUE(clipped);
  clipped = false;
  EXPECT_EQ(to_field(bounded_field(ScalarKind::uint8, 0, 100), 101.0, clipped).scalar.unsigned_integer, 100u);
  EXPECT_TRUE(clipped);
  clipped = false;
  EXPECT_EQ(to_field(bounded_field(ScalarKind::float64), std::nan(""), clipped).scalar.real, 0.0);
  EXPECT_TRUE(clipped);
}

TEST(FmiValues, SixtyFourBitIntegersCrossExactly) {
  bool clipped = false;
  const std::uint64_t big = 18446744073709551615ull;
  EXPECT_EQ(to_field(bounded_field(ScalarKind::uint64), VariableValue(big), clipped).scalar.unsigned_integer, big);
  const std::int64_t low = std::numeric_limits<std::int64_t>::min();
  EXPECT_EQ(to_field(bounded_field(ScalarKind::int64), VariableValue(low), clipped).scalar.integer, low);
  EXPECT_FALSE(clipped);
  FieldValue field;
  field.scalar.unsigned_integer = big - 1;
  const FmuDescription fmi3 = description_of(FmiVersion::fmi3);
  EXPECT_EQ(std::get<std::uint64_t>(
                *to_variable(variable(VariableType::uint64), fmi3, bounded_field(ScalarKind::uint64), field, clipped)),
            big - 1);
  field.scalar.integer = -5;
  EXPECT_EQ(std::get<double>(
                *to_variable(variable(VariableType::float64), fmi3, bounded_field(ScalarKind::int32), field, clipped)),
            -5.0);
  EXPECT_FALSE(clipped);
}

// A field's declared range is what admission checked; an event may still hold more (a DBC raw
// value, another publisher): the variable gets its nearest value, never a wrapped one.
TEST(FmiValues, AnInputBeyondTheVariablesRangeIsSaturatedNotWrapped) {
  const FmuDescription fmi3 = description_of(FmiVersion::fmi3);
  FieldValue field;
  field.scalar.integer = 300;
  bool clipped = false;
  EXPECT_EQ(std::get<std::int64_t>(
                *to_variable(variable(VariableType::int8), fmi3, bounded_field(ScalarKind::int16), field, clipped)),
            127);
  EXPECT_TRUE(clipped);
  clipped = false;
  field.scalar.integer = -1;
  EXPECT_EQ(std::get<std::uint64_t>(
                *to_variable(variable(VariableType::uint32), fmi3, bounded_field(ScalarKind::int16), field, clipped)),
            0u);
  EXPECT_TRUE(clipped);
  clipped = false;
  Variable declared = variable(VariableType::int32);
  declared.min = -10;
  declared.max = 10;
  field.scalar.integer = 11;
  EXPECT_EQ(std::get<std::int64_t>(*to_variable(declared, fmi3, bounded_field(ScalarKind::int32), field, clipped)), 10);
  EXPECT_TRUE(clipped);
}

TEST(FmiValues, AnEnumerationValueThatIsNoItemIsNotGiven) {
  FmuDescription d = description_of(FmiVersion::fmi2);
  TypeDefinition gear;
  gear.name = "Gear";
  gear.type = VariableType::enumeration;
  gear.items = {{"park", 0}, {"drive", 2}};
  d.type_definitions = {gear};
  Variable v = variable(VariableType::enumeration);
  v.declared_type = "Gear";
  FieldValue field;
  field.scalar.unsigned_integer = 2;
  bool clipped = false;
  EXPECT_EQ(std::get<std::int64_t>(*to_variable(v, d, bounded_field(ScalarKind::uint8), field, clipped)), 2);
  field.scalar.unsigned_integer = 1;
  EXPECT_FALSE(to_variable(v, d, bounded_field(ScalarKind::uint8), field, clipped));
}

TEST(ChannelFields, TwoVariablesMayTakeOneField) {
  const ChannelType type = state_type();
  auto fields = ChannelFields::make(type, {"pose.v", "pose.v"});
  ASSERT_TRUE(fields);
  std::vector<FieldValue> slots;
  ASSERT_TRUE(fields.value().read(state_event(3.5, 1, "", 0, false), slots));
  EXPECT_EQ(slots[0].scalar.real, 3.5);
  EXPECT_EQ(slots[1].scalar.real, 3.5);
}

// A DBC multiplexed signal: its place is zero while its selector does not select it, and then it
// is absent, not 0.
TEST(ChannelFields, AConditionalFieldIsAbsentWhileItsSelectorDoesNotSelectIt) {
  ChannelType type;  // as a DBC message with a multiplexed signal gives it (channel_type_from_dbc)
  TypeField mode;
  mode.name = "mode";
  mode.type.scalar = ScalarKind::uint8;
  TypeField code;
  code.name = "code";
  code.type.scalar = ScalarKind::uint16;
  code.present_when = FieldPresence{"mode", 1};
  type.fields = {mode, code};
  auto fields = ChannelFields::make(type, {"code"});
  ASSERT_TRUE(fields);
  std::vector<FieldValue> slots;
  ASSERT_TRUE(fields.value().read(std::vector<std::uint8_t>{1, 0x34, 0x12}, slots));
  EXPECT_TRUE(slots[0].present);
  EXPECT_EQ(slots[0].scalar.unsigned_integer, 0x1234u);
  ASSERT_TRUE(fields.value().read(std::vector<std::uint8_t>{0, 0, 0}, slots));
  EXPECT_FALSE(slots[0].present);
}

TEST(FmiValues, ParametersParseAsTheirTypes) {
  FmuDescription d;
  Variable gain = variable(VariableType::float64);
  gain.causality = Causality::parameter;
  EXPECT_EQ(std::get<double>(parse_value(gain, d, "2.5").value()), 2.5);
  EXPECT_FALSE(parse_value(gain, d, "fast"));
  Variable on = variable(VariableType::boolean);
  EXPECT_EQ(std::get<bool>(parse_value(on, d, "true").value()), true);
  Variable count = variable(VariableType::uint64);
  EXPECT_EQ(std::get<std::uint64_t>(parse_value(count, d, "18446744073709551615").value()), 18446744073709551615ull);
}

// An FMU instance that records what it is given: y = 2u + the number of steps, and the u it had.
class ScriptedInstance final : public FmuInstance {
 public:
  Result<void> set(const Variable& v, const VariableValue& value) override {
    values[v.name] = value;
    ++sets;
    return {};
  }
  Result<VariableValue> get(const Variable& v) override { return values[v.name]; }
  Result<void> initialize(double) override {
    initialized = true;
    return {};
  }
  Result<void> do_step(double time, double step) override {
    if (fail_at && time >= *fail_at) {
      keep_log({"Error", "logStatusError", "step at t=" + std::to_string(time) + " failed"});
      return Error{"fmi2DoStep returned Error" + last_words()};
    }
    times.push_back(time);
    EXPECT_DOUBLE_EQ(step, 0.01);
    values["y"] = 2 * std::get<double>(values["u"]) + static_cast<double>(times.size());
    return {};
  }
  Result<void> terminate() override { return {}; }

  std::map<std::string, VariableValue> values{{"u", 0.0}, {"y", 0.0}};
  std::vector<double> times;
  std::optional<double> fail_at;
  bool initialized = false;
  int sets = 0;
};

class Stepper : public testing::Test {
 protected:
  void SetUp() override {
    ConfigResult loaded = parse_config(
        "segments:\n"
        "  - {name: lan, type: dds, domain: 0}\n"
        "  - {name: viz, type: lcm}\n"
        "channels:\n"
        "  - {name: drive, subject: 0x20, class: srt, period: 10ms, reaction_time: 40ms, publishers: [lan], "
        "subscribers: [viz], type: {fields: [{name: u, type: float64}]}}\n"
        "  - {name: speed, subject: 0x21, class: srt, period: 10ms, reaction_time: 40ms, publishers: [lan], "
        "subscribers: [viz], type: {fields: [{name: y, type: float32}]}}\n",
        "stepper.yaml");
    ASSERT_TRUE(loaded.errors.empty()) << loaded.errors.front().to_string();
    config_ = loaded.config;
    description_.variables = {variable(VariableType::float64), variable(VariableType::float64)};
    description_.variables[0].name = "u";
    description_.variables[0].causality = Causality::input;
    description_.variables[1].name = "y";
    description_.variables[1].causality = Causality::output;
    spec_.name = "plant";
    spec_.segment = "lan";
    spec_.step = std::chrono::milliseconds(10);
    spec_.inputs = {{"u", "drive", "u"}};
    spec_.outputs = {{"y", "speed", "y"}};
  }
  static std::vector<std::uint8_t> drive(double u) {
    std::vector<std::uint8_t> e;
    append(e, u);
    return e;
  }
  static float speed(std::span<const std::uint8_t> e) {
    float y = 0;
    std::memcpy(&y, e.data(), sizeof y);
    return y;
  }

  Config config_;
  FmuDescription description_;
  FmuSpec spec_;
  ScriptedInstance fmu_;
};

TEST_F(Stepper, EachStepTakesTheNewestEventAndCountsTheSkippedOnes) {
  auto stepper = FmuStepper::make(spec_, description_, config_, fmu_);
  ASSERT_TRUE(stepper) << stepper.error().text;
  FmuStepper& s = *stepper.value();
  ASSERT_TRUE(s.start());
  EXPECT_TRUE(fmu_.initialized);

  ASSERT_TRUE(s.step(0));  // no event yet: u keeps its start value
  EXPECT_FLOAT_EQ(speed(s.output_event(0)), 1.0f);
  s.latch(0).offer(drive(1.0));
  s.latch(0).offer(drive(2.0));
  s.latch(0).offer(drive(3.0));  // the newest before the step
  ASSERT_TRUE(s.step(1));
  EXPECT_FLOAT_EQ(speed(s.output_event(0)), 2 * 3.0f + 2);
  ASSERT_TRUE(s.step(2));  // nothing new: the last event's value stays
  EXPECT_FLOAT_EQ(speed(s.output_event(0)), 2 * 3.0f + 3);
  EXPECT_EQ(fmu_.times, (std::vector<double>{0.0, 0.01, 0.02}));

  const auto in = s.input_counters();
  EXPECT_EQ(in[0].taken, 1u);
  EXPECT_EQ(in[0].skipped, 2u);
  EXPECT_EQ(s.output_counters()[0].events, 3u);
  std::vector<InputCounters> copied_in;
  std::vector<OutputCounters> copied_out;
  s.copy_counters(copied_in, copied_out);
  EXPECT_EQ(copied_in[0].channel, "drive");
  EXPECT_EQ(copied_in[0].skipped, 2u);
  ASSERT_TRUE(s.step(3));
  s.copy_counters(copied_in, copied_out);  // the second time: numbers only
  EXPECT_EQ(copied_out[0].channel, "speed");
  EXPECT_EQ(copied_out[0].events, 4u);
}

TEST_F(Stepper, AnEventThatIsNotOfTheTypeIsCountedAndChangesNothing) {
  auto stepper = FmuStepper::make(spec_, description_, config_, fmu_);
  ASSERT_TRUE(stepper);
  FmuStepper& s = *stepper.value();
  ASSERT_TRUE(s.start());
  s.latch(0).offer(drive(4.0));
  ASSERT_TRUE(s.step(0));
  s.latch(0).offer(std::vector<std::uint8_t>{1, 2, 3});
  ASSERT_TRUE(s.step(1));
  EXPECT_FLOAT_EQ(speed(s.output_event(0)), 2 * 4.0f + 2);
  EXPECT_EQ(s.input_counters()[0].decode_errors, 1u);
}

// A receive thread offers while the step thread takes (what TSan watches in scripts/test): every
// event is either taken or counted as skipped, and what is taken is whole.
TEST(InputLatch, EveryOfferedEventIsTakenOrCountedAsSkipped) {
  InputLatch latch;
  constexpr std::uint64_t kEvents = 20'000;
  std::thread receiver([&] {
    for (std::uint64_t i = 1; i <= kEvents; ++i) {
      std::vector<std::uint8_t> e;
      append(e, i);
      append(e, ~i);
      latch.offer(e);
    }
  });
  std::uint64_t accounted = 0, last = 0;
  std::vector<std::uint8_t> taken;
  while (accounted < kEvents) {
    std::uint64_t arrived = 0;
    if (!latch.take(taken, arrived)) continue;
    accounted += arrived;
    ASSERT_EQ(taken.size(), 16u);
    std::uint64_t value = 0, check = 0;
    std::memcpy(&value, taken.data(), 8);
    std::memcpy(&check, taken.data() + 8, 8);
    ASSERT_EQ(check, ~value);  // never half of one event and half of another
    ASSERT_GT(value, last);    // the newest, never an older one again
    last = value;
  }
  receiver.join();
  EXPECT_EQ(accounted, kEvents);
  EXPECT_EQ(last, kEvents);
}

TEST_F(Stepper, AFailedStepCarriesTheFmusOwnMessage) {
  fmu_.fail_at = 0.02;
  auto stepper = FmuStepper::make(spec_, description_, config_, fmu_);
  ASSERT_TRUE(stepper);
  FmuStepper& s = *stepper.value();
  ASSERT_TRUE(s.start());
  ASSERT_TRUE(s.step(0));
  ASSERT_TRUE(s.step(1));
  const auto failed = s.step(2);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().text.find("the FMU said: step at t=0.02"), std::string::npos) << failed.error().text;
  EXPECT_NE(fmu_.recent_log_text().find("[Error] logStatusError: step at t=0.02"), std::string::npos);
}

TEST_F(Stepper, AMappingToAFieldTheTypeLacksIsRefused) {
  spec_.outputs = {{"y", "speed", "z"}};
  const auto stepper = FmuStepper::make(spec_, description_, config_, fmu_);
  ASSERT_FALSE(stepper);
  EXPECT_NE(stepper.error().text.find("channel 'speed': the type has no field 'z'"), std::string::npos);
}

}  // namespace
}  // namespace cosmic::fmi

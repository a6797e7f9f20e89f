// The `fmus:` section (docs/fmu.md, docs/yaml-reference.md): an FMU read at load (its file among the
// included ones), its mappings and parameters checked against its description and the channels'
// types, channels taking P/S segments from it as from a component, and every mistake located.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "config_test_support.hpp"
#include "cosmic/build_paths.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"
#include "fmu_test_support.hpp"

namespace cosmic {
namespace {

namespace fs = std::filesystem;

class FmuConfig : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("fmu_config_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const std::string library = test::file_bytes(build_paths::fmi_test_model);
    ASSERT_TRUE(test::write_zip((dir_ / "plant.fmu").string(), {{"modelDescription.xml", test::kFmi2Description},
                                                                {"binaries/linux64/Plant.so", library}}));
    ASSERT_TRUE(test::write_zip((dir_ / "win.fmu").string(), {{"modelDescription.xml", test::kFmi2Description},
                                                              {"binaries/win64/Plant.dll", "MZ"}}));
    ASSERT_TRUE(test::write_zip((dir_ / "me.fmu").string(), {{"modelDescription.xml",
                                                              "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"M\" "
                                                              "guid=\"g\">\n<ModelExchange modelIdentifier=\"M\"/>\n"
                                                              "</fmiModelDescription>"}}));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string file() const { return (dir_ / "g.yaml").string(); }

  // Channels without publishers/subscribers: they come from the FMU and the component.
  static std::string document(const std::string& fmu) {
    return "segments:\n"
           "  - {name: lan, type: dds, domain: 0}\n"
           "  - {name: viz, type: lcm, url: \"udpm://239.255.76.67:7667?ttl=0\"}\n"
           "channels:\n"
           "  - name: command\n"
           "    subject: 0x10\n"
           "    class: srt\n"
           "    period: 10ms\n"
           "    reaction_time: 40ms\n"
           "    type: {fields: [{name: speed, type: float32, min: -20, max: 20}, {name: mode, type: enum, "
           "underlying: uint8, values: {off: 1, on: 2}}]}\n"
           "  - name: state\n"
           "    subject: 0x11\n"
           "    class: srt\n"
           "    period: 10ms\n"
           "    reaction_time: 40ms\n"
           "    type: {fields: [{name: pose, type: record, fields: [{name: v, type: float64}, {name: n, type: "
           "uint8}]}, {name: ready, type: bool}]}\n"
           "  - {name: raw, subject: 0x12, class: nrt, period: 10ms, publishers: [lan], subscribers: [viz]}\n"
           "components:\n"
           "  - {name: driver, segment: viz, publishes: [command], subscribes: [state]}\n"
           "fmus:\n" +
           fmu;
  }

  static std::string plant(const std::string& extra = "", const std::string& outputs =
                                                              "{y: state.pose.v, count: "
                                                              "state.pose.n, ready: state.ready}") {
    return "  - name: plant\n"
           "    fmu: plant.fmu\n"
           "    segment: lan\n"
           "    inputs: {u: command.speed, mode: command.mode}\n"
           "    outputs: " +
           outputs + "\n" + extra;
  }

  // `document` with the lines after the state channel's class replaced by `lines` up to its
  // reaction_time (its period, and what else the test gives it).
  static std::string with_state(std::string document, const std::string& lines) {
    const std::string was = "    subject: 0x11\n    class: srt\n    period: 10ms\n";
    document.replace(document.find(was), was.size(), "    subject: 0x11\n    class: srt\n" + lines);
    return document;
  }

  fs::path dir_;
};

TEST_F(FmuConfig, AnFmuIsReadAtLoadAndCountsAsAComponent) {
  const ConfigResult r =
      parse_config(document(plant("    step: 20ms\n    parameters: {gain: 2.5, label: rig}\n")), file());
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  ASSERT_EQ(r.config.fmus.size(), 1u);
  const FmuSpec& f = r.config.fmus[0];
  EXPECT_EQ(f.name, "plant");
  EXPECT_EQ(f.fmu, (dir_ / "plant.fmu").string());
  EXPECT_EQ(f.segment, "lan");
  EXPECT_EQ(f.step, Nanos(20'000'000));
  EXPECT_EQ(f.fmi_version, "2.0");
  EXPECT_EQ(f.model_identifier, "Plant");
  EXPECT_EQ(f.inputs, (std::vector<FmuVariableMapping>{{"u", "command", "speed"}, {"mode", "command", "mode"}}));
  EXPECT_EQ(f.outputs.size(), 3u);
  EXPECT_EQ(f.outputs[0], (FmuVariableMapping{"y", "state", "pose.v"}));
  EXPECT_EQ(f.parameters, (std::vector<FmuParameter>{{"gain", "2.5"}, {"label", "rig"}}));
  EXPECT_EQ(f.publishes(), std::vector<std::string>{"state"});
  EXPECT_EQ(f.subscribes(), std::vector<std::string>{"command"});
  EXPECT_NE(std::find(r.included_files.begin(), r.included_files.end(), f.fmu), r.included_files.end());
  // P/S segments as from a component: state published on lan (the FMU), received on viz (driver).
  const ChannelSpec* state = r.config.find_channel("state");
  EXPECT_EQ(state->publishers, std::vector<std::string>{"lan"});
  EXPECT_EQ(state->subscribers, std::vector<std::string>{"viz"});
  const ChannelSpec* command = r.config.find_channel("command");
  EXPECT_EQ(command->publishers, std::vector<std::string>{"viz"});
  EXPECT_EQ(command->subscribers, std::vector<std::string>{"lan"});
}

TEST_F(FmuConfig, TheStepDefaultsToTheFmusDefaultExperiment) {
  const ConfigResult r = parse_config(document(plant()), file());
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  EXPECT_EQ(r.config.fmus[0].step, Nanos(10'000'000));  // stepSize="0.01"
}

TEST_F(FmuConfig, EveryMistakeIsLocated) {
  struct Case {
    std::string fmu;
    std::string expected;
  };
  const std::string at = "g.yaml:";
  const std::vector<Case> cases = {
      {"  - {name: plant, fmu: me.fmu, segment: lan, step: 10ms}\n",
       "fmus[0].fmu: " + (dir_ / "me.fmu").string() + ": modelDescription.xml:1: no <CoSimulation> element"},
      {"  - {name: plant, fmu: win.fmu, segment: lan, step: 10ms}\n",
       "fmus[0].fmu: " + (dir_ / "win.fmu").string() + " has no binary for this platform"},
      {"  - {name: plant, fmu: nowhere.fmu, segment: lan, step: 10ms}\n", "fmus[0].fmu: cannot open"},
      {"  - {name: plant, fmu: plant.fmu, segment: lab}\n", "g.yaml:21:44: fmus[0].segment: unknown segment 'lab'"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, step: 0ms}\n", "fmus[0].step:"},
      {plant("", "{y: state.pose.v, count: state.pose.n, ready: state.ready, nope: state.ready}"),
       "fmus[0].outputs.nope: the FMU has no variable 'nope'"},
      {plant("", "{u: state.pose.v, count: state.pose.n, ready: state.ready}"),
       "fmus[0].outputs.u: variable 'u' is input, not output (one of the FMU's outputs: y, count, ready)"},
      {plant("", "{y: gone.v}"),
       "fmus[0].outputs.y: unknown channel 'gone' (one of the typed channels: command, state)"},
      {plant("", "{y: raw.v}"), "fmus[0].outputs.y: channel 'raw' has no type"},
      {plant("", "{y: state.pose.w}"),
       "fmus[0].outputs.y: channel 'state' has no field 'pose.w' (one of its fields: "
       "pose.v, pose.n, ready)"},
      {plant("", "{y: state.pose}"), "fmus[0].outputs.y: Real variable 'y' cannot carry state.pose"},
      {plant("", "{y: state.pose.v, count: state.pose.n, ready: state.pose.v}"),
       "fmus[0].outputs.ready: Boolean variable 'ready' cannot carry state.pose.v (float64): Boolean carries bool "
       "fields"},
      {plant("", "{y: state.pose.v, count: state.ready, ready: state.ready}"),
       "Integer variable 'count' cannot carry state.ready (bool)"},
      {plant("", "{y: state.pose.v, ready: state.ready}"),
       "fmus[0].outputs: the outputs set fields of 'state' but not pose.n"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, inputs: {u: command.mode}}\n",
       "Real variable 'u' cannot carry command.mode"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, inputs: {mode: command.speed}}\n",
       "Enumeration variable 'mode' cannot carry command.speed (float32)"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, inputs: {u: command}}\n",
       "fmus[0].inputs.u: 'command' is not channel.field"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, parameters: {gain: 11}}\n",
       "fmus[0].parameters.gain: '11' is outside the variable's range 0..10"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, parameters: {gain: fast}}\n",
       "fmus[0].parameters.gain: 'fast' is not a number"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, parameters: {twice: 1}}\n",
       "fmus[0].parameters.twice: variable 'twice' is calculatedParameter, fixed: only a fixed or tunable parameter is "
       "set"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, parameters: {y: 1}}\n",
       "variable 'y' is output, continuous: only a fixed or tunable parameter is set (one of the FMU's parameters: "
       "label, "
       "gain)"},
      {"  - {name: driver, fmu: plant.fmu, segment: lan}\n",
       "fmus[0].name: name 'driver' is taken (a name not used by a component or another FMU)"},
      {"  - {name: plant, fmu: plant.fmu, segment: lan, colour: red}\n", "fmus[0].colour"},
  };
  for (const Case& c : cases) test::expect_refused_with(parse_config(document(c.fmu), file()), c.expected);
}

// The FMU publishes each output channel once per step (docs/fmu.md, "Timing and admission").
TEST_F(FmuConfig, AStepShorterThanAnOutputChannelsPeriodIsLocated) {
  const ConfigResult r = parse_config(document(plant("    step: 5ms\n")), file());
  ASSERT_EQ(r.errors.size(), 1u) << test::errors_text(r);
  EXPECT_EQ(r.errors[0].to_string(),
            file() +
                ":26:11: fmus[0].step: 5ms publishes 'state' every 5 ms, faster than its period 10 ms (a step at "
                "least the period of every output channel)");
  // A step from the FMU's DefaultExperiment (10 ms) is located at the entry.
  const ConfigResult defaulted = parse_config(with_state(document(plant()), "    period: 20ms\n"), file());
  ASSERT_EQ(defaulted.errors.size(), 1u) << test::errors_text(defaulted);
  EXPECT_EQ(defaulted.errors[0].to_string(),
            file() +
                ":21:5: fmus[0].step: no step given: the FMU's DefaultExperiment stepSize publishes 'state' every 10 "
                "ms, faster than its period 20 ms (a step at least the period of every output channel)");
  // Equal to the period, and longer, are fine; inputs are not published.
  EXPECT_TRUE(parse_config(document(plant("    step: 10ms\n")), file()).ok());
  EXPECT_TRUE(parse_config(document(plant("    step: 30ms\n")), file()).ok());
}

TEST_F(FmuConfig, OutputChannelsNameTheFmuAndAdmissionJudgesItsStep) {
  // The end-to-end latency (21 ms over the segments' default bounds) within temp_validity, the step not.
  const std::string text = with_state(document(plant("    step: 40ms\n")),
                                      "    period: 10ms\n    temp_validity: 30ms\n    omission_degree: 1\n");
  const ConfigResult r = parse_config(text, file());
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  EXPECT_EQ(r.config.find_channel("state")->fmu_publishers,
            (std::vector<FmuPublisher>{{"plant", "lan", Nanos(40'000'000)}}));
  EXPECT_TRUE(r.config.find_channel("command")->fmu_publishers.empty());  // the FMU subscribes it
  const AdmissionReport report = admit_all(r.config);
  const ChannelReport* state = report.find("state");
  ASSERT_NE(state, nullptr);
  EXPECT_EQ(state->verdict, Verdict::degraded);
  EXPECT_EQ(state->reasons,
            std::vector<std::string>{"fmu plant publishes every 40 ms (its step), longer than temp_validity 30 ms: "
                                     "between two steps subscribers hold a value older than its validity"});
  // The checks on the FMU's publisher hop carry the numbers (cosmicctl check --json, cosmicctl channel).
  const HopReport& lan = state->hops[0];
  ASSERT_EQ(lan.segment, "lan");
  const auto check = [&](const std::string& name) {
    const auto it = std::find_if(lan.checks.begin(), lan.checks.end(), [&](const Check& c) { return c.check == name; });
    return it == lan.checks.end() ? Check{} : *it;
  };
  EXPECT_TRUE(check("fmu_rate").ok);
  EXPECT_DOUBLE_EQ(check("fmu_rate").limit, 0.010);
  EXPECT_FALSE(check("fmu_validity").ok);
  EXPECT_DOUBLE_EQ(check("fmu_validity").value, 0.040);
  EXPECT_DOUBLE_EQ(check("fmu_validity").limit, 0.030);
  // cosmicctl check's table shows the reason under the channel.
  const std::string shown = render_text(report);
  EXPECT_NE(shown.find("    - fmu plant publishes every 40 ms (its step), longer than temp_validity 30 ms"),
            std::string::npos)
      << shown;
  // A channel bound at run time takes the running configuration's FMUs.
  const ChannelsResult bound = parse_channels(
      "{name: state, subject: 0x11, class: nrt, period: 10ms, publishers: [lan], subscribers: [viz], type: {fields: "
      "[{name: ready, type: bool}]}}",
      "bind.yaml", r.config);
  ASSERT_TRUE(bound.ok()) << (bound.errors.empty() ? "" : bound.errors[0].to_string());
  EXPECT_EQ(bound.channels[0].fmu_publishers, r.config.find_channel("state")->fmu_publishers);
}

// A refused FMU leaves its channels without the segment it would have given them: its own errors
// say so, not a second error on each channel.
TEST_F(FmuConfig, ARefusedFmuIsReportedOnceNotAgainOnItsChannels) {
  const ConfigResult r = parse_config(document(plant("    parameters: {gain: 11}\n")), file());
  ASSERT_EQ(r.errors.size(), 1u) << test::errors_text(r);
  EXPECT_NE(r.errors[0].to_string().find("fmus[0].parameters.gain"), std::string::npos);
  // A refused output is not reported again as a field the outputs leave unset.
  const ConfigResult output =
      parse_config(document(plant("", "{y: state.pose.v, count: state.pose.n, ready: state.pose.v}")), file());
  ASSERT_EQ(output.errors.size(), 1u) << test::errors_text(output);
  EXPECT_NE(output.errors[0].to_string().find("fmus[0].outputs.ready"), std::string::npos);
  // A channel nobody publishes, with a loaded FMU subscribing it, still lacks publishers.
  const ConfigResult unpublished = parse_config(
      "segments:\n"
      "  - {name: lan, type: dds, domain: 0}\n"
      "channels:\n"
      "  - {name: c, subject: 0x10, class: nrt, period: 10ms, type: {fields: [{name: v, type: float64}]}}\n"
      "fmus:\n"
      "  - {name: plant, fmu: plant.fmu, segment: lan, inputs: {u: c.v}}\n",
      file());
  test::expect_refused_with(unpublished, "channels[0].publishers: no publishers given and none derived");
}

// Channels that name their segments must agree with the FMU, as with a component.
TEST_F(FmuConfig, AnOutputChannelNeedsTheFmusSegmentAmongItsPublishers) {
  const std::string text =
      "segments:\n"
      "  - {name: lan, type: dds, domain: 0}\n"
      "  - {name: viz, type: lcm, url: \"udpm://239.255.76.67:7667?ttl=0\"}\n"
      "channels:\n"
      "  - {name: out, subject: 0x11, class: srt, period: 10ms, reaction_time: 40ms, publishers: [viz],\n"
      "     subscribers: [lan],\n"
      "     type: {fields: [{name: ready, type: bool}]}}\n"
      "fmus:\n"
      "  - {name: plant, fmu: plant.fmu, segment: lan, outputs: {ready: out.ready}}\n";
  test::expect_refused_with(parse_config(text, file()),
                            "g.yaml:9:66: fmus[0].outputs.ready: FMU 'plant' on segment 'lan' publishes 'out', which "
                            "the gateway does not bind there (an FMU on a segment listed in its publishers (viz))");
}

}  // namespace
}  // namespace cosmic

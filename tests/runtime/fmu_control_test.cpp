// FMUs as components at run time (issue 38, docs/fmu.md "Timing and admission"): the runners'
// reports (fmu_report) kept per FMU of the running configuration, every refusal keeping nothing, who
// may send them, a reload dropping the reports of FMUs it no longer has, the `fmus` answer, a
// channel answer's FMU part, and an FMU whose worst step overran its step flagging its output
// channels violated at run time. The protocol is called directly (no socket): every answer is
// immediate and the test owns the control thread.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "control_fixture.hpp"
#include "cosmic/control_protocol.hpp"
#include "cosmic/fmu_reports.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic {
namespace {

using Json = nlohmann::json;
using namespace std::chrono_literals;

bool logged(control_test::QuietLogger& log, const std::string& text) {
  std::lock_guard lock(log.mutex);
  return std::any_of(log.lines.begin(), log.lines.end(),
                     [&](const auto& l) { return l.find(text) != std::string::npos; });
}

// speed: lan -> viz (the control tests' configuration); drive: viz -> lan. The controller FMU on
// viz takes speed and sets drive; the plant FMU on lan takes drive and sets speed.
const std::string kChannels = std::string(control_test::kConfig) +
                              "  - {name: drive, subject: 2, class: srt, period: 10ms, reaction_time: 20ms, "
                              "omission_degree: 1, publishers: [viz], subscribers: [lan]}\n";

FmuSpec fmu(const std::string& name, const std::string& segment, FmuVariableMapping input, FmuVariableMapping output) {
  FmuSpec f;
  f.name = name;
  f.fmu = "/etc/cosmic/" + name + ".fmu";
  f.segment = segment;
  f.step = Nanos(10ms);
  f.inputs = {std::move(input)};
  f.outputs = {std::move(output)};
  f.fmi_version = "2.0";
  f.model_identifier = name;
  return f;
}

// The configuration with the FMUs named in `names` (of speed_fmu and plant).
Config config_with(const std::vector<std::string>& names) {
  Config config = parse_config(kChannels, "test.yaml").config;
  for (const auto& name : names) {
    if (name == "speed_fmu")
      config.fmus.push_back(fmu("speed_fmu", "viz", {"actual_speed", "speed", "v"}, {"u", "drive", "v"}));
    if (name == "plant") config.fmus.push_back(fmu("plant", "lan", {"u", "drive", "v"}, {"y", "speed", "v"}));
  }
  return config;
}

// A running runner's report; what it skipped counted per input variable (speed_fmu) or channel (plant).
Json report(const std::string& name, std::uint64_t worst_step_ns = 412'000) {
  return Json{{"command", "fmu_report"},
              {"name", name},
              {"state", "running"},
              {"step_ns", 10'000'000},
              {"steps", 1234},
              {"late_steps", 0},
              {"worst_step_ns", worst_step_ns},
              {"p99_step_ns", 300'000},
              {"skipped", name == "plant" ? Json{{"drive", 2}} : Json{{"actual_speed", 3}}}};
}

class FmuControl : public testing::Test {
 protected:
  FmuControl()
      : gateway([](const SegmentSpec& spec, const GatewayIdentity&,
                   Logger&) { return std::make_unique<MemoryAdapter>(spec.name); },
                log, 0x42) {
    EXPECT_TRUE(gateway.start(config_with({"speed_fmu", "plant"})).applied);
  }
  ~FmuControl() override { gateway.stop(); }

  // A protocol whose reload reads `reloaded`.
  ControlProtocol& serve(AccessPolicy policy = {}) {
    protocol = std::make_unique<ControlProtocol>(
        gateway,
        [this] {
          return ConfigResult{reloaded, {}, {}};
        },
        std::move(policy), log);
    return *protocol;
  }
  Json call(const Json& request) { return Json::parse(protocol->handle(request.dump(), PeerCredentials{})); }
  Json fmu_entry(const std::string& name) {
    const Json answer = call({{"command", "fmus"}});
    for (const auto& f : answer["fmus"])
      if (f["name"] == name) return f;
    return Json();
  }

  control_test::QuietLogger log;
  Gateway gateway;
  Config reloaded = config_with({"plant"});
  std::unique_ptr<ControlProtocol> protocol;
};

TEST_F(FmuControl, AReportIsKeptAndShownInFmusAndInTheChannelsItTouches) {
  serve();
  const Json before = call({{"command", "fmus"}});
  ASSERT_EQ(before["ok"], true) << before;
  ASSERT_EQ(before["fmus"].size(), 2u);
  const Json& listed = before["fmus"][0];
  EXPECT_EQ(listed["name"], "speed_fmu");
  EXPECT_EQ(listed["fmu"], "/etc/cosmic/speed_fmu.fmu");
  EXPECT_EQ(listed["fmi_version"], "2.0");
  EXPECT_EQ(listed["segment"], "viz");
  EXPECT_EQ(listed["step_ns"], 10'000'000);
  EXPECT_EQ(listed["publishes"], Json::array({"drive"}));
  EXPECT_EQ(listed["subscribes"], Json::array({"speed"}));
  EXPECT_TRUE(listed["report"].is_null());  // never reported
  EXPECT_TRUE(listed["overrun"].is_null());

  EXPECT_EQ(call(report("speed_fmu")), Json({{"ok", true}}));
  const Json kept = fmu_entry("speed_fmu")["report"];
  EXPECT_EQ(kept["state"], "running");
  EXPECT_EQ(kept["step_ns"], 10'000'000);
  EXPECT_EQ(kept["steps"], 1234);
  EXPECT_EQ(kept["late_steps"], 0);
  EXPECT_EQ(kept["worst_step_ns"], 412'000);
  EXPECT_EQ(kept["p99_step_ns"], 300'000);
  EXPECT_EQ(kept["skipped"], Json({{"actual_speed", 3}}));
  EXPECT_EQ(kept["message"], "");
  EXPECT_GE(kept["age_s"].get<double>(), 0.0);
  EXPECT_EQ(kept["stale"], false);
  EXPECT_TRUE(fmu_entry("plant")["report"].is_null());
  // The latest report replaces the one before.
  Json later = report("speed_fmu");
  later["steps"] = 1334;
  ASSERT_EQ(call(later)["ok"], true);
  EXPECT_EQ(fmu_entry("speed_fmu")["report"]["steps"], 1334);

  // A channel's answer names each FMU publishing or subscribing it, with what it reported.
  for (const Json& drive :
       {call({{"command", "channel"}, {"name", "drive"}})["channel"], call({{"command", "channels"}})["channels"][1]}) {
    ASSERT_EQ(drive["name"], "drive");
    ASSERT_EQ(drive["fmus"].size(), 2u) << drive["fmus"];
    EXPECT_EQ(drive["fmus"][0]["name"], "speed_fmu");
    EXPECT_EQ(drive["fmus"][0]["role"], "publisher");
    EXPECT_EQ(drive["fmus"][0]["segment"], "viz");
    EXPECT_EQ(drive["fmus"][0]["step_ns"], 10'000'000);
    EXPECT_EQ(drive["fmus"][0]["report"]["worst_step_ns"], 412'000);
    EXPECT_EQ(drive["fmus"][0]["report"]["late_steps"], 0);
    EXPECT_EQ(drive["fmus"][1]["name"], "plant");
    EXPECT_EQ(drive["fmus"][1]["role"], "subscriber");
    EXPECT_TRUE(drive["fmus"][1]["report"].is_null());
  }
}

TEST_F(FmuControl, EachRefusedReportKeepsNothing) {
  serve();
  ASSERT_EQ(call(report("speed_fmu"))["ok"], true);
  struct Case {
    Json request;
    std::string code;
    std::string message;
  };
  auto with = [](const std::string& key, const Json& value) {
    Json r = report("speed_fmu", 999);
    r[key] = value;
    return r;
  };
  auto without = [](const std::string& key) {
    Json r = report("speed_fmu", 999);
    r.erase(key);
    return r;
  };
  const std::vector<Case> cases = {
      {report("nobody", 999), "not_found",
       "no FMU named 'nobody' in the running configuration (its FMUs: speed_fmu, plant)"},
      {without("name"), "bad_request", "\"name\" (string) is required: the FMU's name in fmus:"},
      {with("name", 7), "bad_request", "\"name\" (string) is required: the FMU's name in fmus:"},
      {without("state"), "bad_request", "\"state\" (string) is required"},
      {with("state", "paused"), "bad_request", "unknown state 'paused' (starting, running, stopped or failed)"},
      {without("steps"), "bad_request", "\"steps\" is missing"},
      {without("late_steps"), "bad_request", "\"late_steps\" is missing"},
      {without("p99_step_ns"), "bad_request", "\"p99_step_ns\" is missing"},
      {without("skipped"), "bad_request", "\"skipped\" is missing"},
      {with("steps", -1), "bad_request", "\"steps\" must be a whole number >= 0, not -1"},
      {with("worst_step_ns", 1.5), "bad_request", "\"worst_step_ns\" must be a whole number >= 0, not 1.5"},
      {with("step_ns", "10ms"), "bad_request", "\"step_ns\" must be a whole number >= 0, not \"10ms\""},
      {with("step_ns", 0), "bad_request", "\"step_ns\" must be > 0"},
      // A duration beyond what a signed 64-bit count of nanoseconds holds (cosmicctl would print it
      // negative, and an overrun check would compare a wrapped value).
      {with("worst_step_ns", std::uint64_t{9'223'372'036'854'775'808u}), "bad_request",
       "\"worst_step_ns\" must be at most 9223372036854775807 ns, not 9223372036854775808"},
      {with("p99_step_ns", std::uint64_t{18'446'744'073'709'551'615u}), "bad_request",
       "\"p99_step_ns\" must be at most 9223372036854775807 ns, not 18446744073709551615"},
      {with("skipped", Json::array()), "bad_request", "\"skipped\" must be an object of input: count, not array"},
      {with("skipped", {{"wheel", 1}}), "bad_request",
       "\"skipped\" counts 'wheel', none of the FMU's inputs (actual_speed, speed)"},
      {with("skipped", {{"speed", -2}}), "bad_request", "\"skipped\": \"speed\" must be a whole number >= 0, not -2"},
      {with("message", 5), "bad_request", "\"message\" must be a string"},
  };
  for (const Case& c : cases) {
    const Json answer = call(c.request);
    EXPECT_EQ(answer["ok"], false) << c.request;
    EXPECT_EQ(answer["error"]["code"], c.code) << c.request;
    EXPECT_EQ(answer["error"]["message"], "fmu_report: " + c.message + "; nothing kept") << c.request;
    EXPECT_EQ(fmu_entry("speed_fmu")["report"]["worst_step_ns"], 412'000) << c.request;  // the accepted one
  }
  EXPECT_TRUE(fmu_entry("plant")["report"].is_null());
  // The longest duration itself is a duration.
  EXPECT_EQ(call(with("worst_step_ns", std::uint64_t{9'223'372'036'854'775'807u}))["ok"], true);
  EXPECT_EQ(fmu_entry("speed_fmu")["report"]["worst_step_ns"], 9'223'372'036'854'775'807);
}

// A report binds nothing but can flag channels violated: its own permission (AccessPolicy::may_report).
TEST_F(FmuControl, WhoMayReportIsAPermissionOfItsOwn) {
  AccessPolicy readers_only;
  readers_only.may_report = [](const PeerCredentials&) { return false; };
  serve(readers_only);
  const Json denied = call(report("speed_fmu"));
  EXPECT_EQ(denied["error"]["code"], "permission_denied");
  EXPECT_EQ(denied["error"]["message"], "uid 0 may not report an FMU's state (fmu_report)");
  EXPECT_TRUE(logged(log, "may not run fmu_report"));
  EXPECT_TRUE(fmu_entry("speed_fmu")["report"].is_null());
  // A runner that may report and not read.
  AccessPolicy runner;
  runner.may_read = [](const PeerCredentials&) { return false; };
  runner.may_modify = [](const PeerCredentials&) { return false; };
  serve(runner);
  EXPECT_EQ(call(report("speed_fmu"))["ok"], true);
  EXPECT_EQ(call({{"command", "fmus"}})["error"]["code"], "permission_denied");
}

TEST_F(FmuControl, AReloadDropsTheReportsOfFmusItNoLongerHas) {
  serve();
  ASSERT_EQ(call(report("speed_fmu"))["ok"], true);
  ASSERT_EQ(call(report("plant"))["ok"], true);
  const Json reloaded_answer = call({{"command", "reload"}});
  ASSERT_EQ(reloaded_answer["ok"], true) << reloaded_answer;
  const Json fmus = call({{"command", "fmus"}})["fmus"];
  ASSERT_EQ(fmus.size(), 1u);
  EXPECT_EQ(fmus[0]["name"], "plant");
  EXPECT_EQ(fmus[0]["report"]["steps"], 1234);  // kept: still configured
  EXPECT_EQ(call(report("speed_fmu"))["error"]["code"], "not_found");
  // Configured again, it has no report until its runner sends one.
  reloaded = config_with({"speed_fmu", "plant"});
  ASSERT_EQ(call({{"command", "reload"}})["ok"], true);
  EXPECT_TRUE(fmu_entry("speed_fmu")["report"].is_null());
  EXPECT_EQ(fmu_entry("plant")["report"]["steps"], 1234);
}

TEST_F(FmuControl, AWorstStepBeyondTheStepFlagsTheOutputChannelsViolated) {
  ControlProtocol& p = serve();
  const std::string reason = "fmu speed_fmu's worst step 12.1 ms exceeds its step 10 ms";
  ASSERT_EQ(call(report("speed_fmu", 12'100'000))["ok"], true);
  EXPECT_EQ(fmu_entry("speed_fmu")["overrun"], reason);
  const Json drive = call({{"command", "channel"}, {"name", "drive"}})["channel"];
  EXPECT_EQ(drive["fmus"][0]["overrun"], reason);
  // Its input channel is not flagged.
  EXPECT_TRUE(call({{"command", "channel"}, {"name", "speed"}})["channel"]["fmus"][0]["overrun"].is_null());
  const auto overruns = p.fmu_overruns(std::chrono::steady_clock::now());
  EXPECT_EQ(overruns, (std::map<std::string, std::string>{{"drive", reason}}));

  // What the daemon does every 250 ms: the gateway judges drive violated, as for a miss.
  gateway.set_reported_violations(overruns);
  gateway.refresh_runtime(Nanos(1s));
  EXPECT_EQ(call({{"command", "channel"}, {"name", "drive"}})["channel"]["runtime_state"], "violated");
  EXPECT_EQ(call({{"command", "channel"}, {"name", "speed"}})["channel"]["runtime_state"], "bound");
  EXPECT_EQ(call({{"command", "status"}})["channels"]["violated"], 1);
  EXPECT_TRUE(logged(log, "channel drive violated its admitted bounds: " + reason));

  // Within its step again: bound after a clean interval without an overrun.
  ASSERT_EQ(call(report("speed_fmu", 4'000'000))["ok"], true);
  EXPECT_TRUE(fmu_entry("speed_fmu")["overrun"].is_null());
  gateway.set_reported_violations(p.fmu_overruns(std::chrono::steady_clock::now()));
  gateway.refresh_runtime(Nanos(2s));
  EXPECT_EQ(call({{"command", "channel"}, {"name", "drive"}})["channel"]["runtime_state"], "violated");
  gateway.refresh_runtime(Nanos(1s) + gateway.config().gateway.clean_interval);
  EXPECT_EQ(call({{"command", "channel"}, {"name", "drive"}})["channel"]["runtime_state"], "bound");
}

// Staleness needs time to pass: FmuReports is given the clock.
TEST(FmuReports, AStaleReportIsShownSoAndFlagsNothing) {
  const std::vector<FmuSpec> fmus = config_with({"speed_fmu", "plant"}).fmus;
  FmuReports reports;
  const auto t0 = FmuReports::Clock::time_point{} + 100s;
  // Numbers as a program builds them (signed), not only as a request line parses them (unsigned).
  ASSERT_EQ(reports.accept(report("speed_fmu", 12'100'000), fmus, t0)["ok"], true);
  EXPECT_EQ(reports.overruns(fmus, t0 + 3s).size(), 1u);
  const Json fresh = reports.fmus_answer(fmus, t0 + 3s)["fmus"][0];
  EXPECT_EQ(fresh["report"]["stale"], false);
  EXPECT_DOUBLE_EQ(fresh["report"]["age_s"].get<double>(), 3.0);
  const Json stale = reports.fmus_answer(fmus, t0 + 3s + 1ms)["fmus"][0];
  EXPECT_EQ(stale["report"]["stale"], true);
  EXPECT_TRUE(stale["overrun"].is_null());
  EXPECT_TRUE(reports.overruns(fmus, t0 + 3s + 1ms).empty());
  // Two FMUs overrunning on one channel: both reasons.
  std::vector<FmuSpec> two = fmus;
  two[1].outputs = {{"y", "drive", "w"}};
  ASSERT_EQ(reports.accept(report("plant", 20'000'000), two, t0)["ok"], true);
  EXPECT_EQ(reports.overruns(two, t0),
            (std::map<std::string, std::string>{{"drive",
                                                 "fmu speed_fmu's worst step 12.1 ms exceeds its step 10 ms; fmu "
                                                 "plant's worst step 20 ms exceeds its step 10 ms"}}));
}

}  // namespace
}  // namespace cosmic

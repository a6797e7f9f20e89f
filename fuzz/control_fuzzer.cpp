// The control protocol parser: one request line from a client of the control socket, against a
// running gateway on in-memory segments (bind, unbind and reload really run). Every line gets
// exactly one answer line that is a JSON object with "ok"; nothing crashes or hangs.
#include <cstdint>
#include <memory>
#include <string_view>

#include "cosmic/control_protocol.hpp"
#include "cosmic/memory_adapter.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

constexpr const char* kConfig = R"(
gateway: {name: fuzz}
segments:
  - {name: lan, type: dds, latency_bound: 1ms}
  - {name: viz, type: lcm, latency_bound: 2ms}
channels:
  - {name: speed, subject: 1, class: srt, period: 10ms, reaction_time: 20ms, omission_degree: 1, publishers: [lan], subscribers: [viz]}
)";

class SilentLogger final : public cosmic::Logger {
 public:
  void log(cosmic::LogLevel, std::string_view) override {}
};

struct Harness {
  Harness()
      : gateway([](const cosmic::SegmentSpec& spec, const cosmic::GatewayIdentity&,
                   cosmic::Logger&) { return std::make_unique<cosmic::MemoryAdapter>(spec.name); },
                log, 0x42),
        protocol(
            gateway, [] { return cosmic::parse_config(kConfig, "reload.yaml"); }, cosmic::AccessPolicy{}, log) {
    gateway.start(with_fmu(cosmic::parse_config(kConfig, "fuzz.yaml").config));
  }
  // An FMU of the configuration (set in code: an fmus: entry reads its file), so fmu_report
  // requests reach every check of a report.
  static cosmic::Config with_fmu(cosmic::Config config) {
    cosmic::FmuSpec fmu;
    fmu.name = "speed_fmu";
    fmu.fmu = "/fuzz/speed.fmu";
    fmu.segment = "viz";
    fmu.inputs = {{"actual_speed", "speed", "v"}};
    fmu.fmi_version = "2.0";
    config.fmus.push_back(std::move(fmu));
    return config;
  }
  SilentLogger log;
  cosmic::Gateway gateway;
  cosmic::ControlProtocol protocol;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // One gateway for the whole run, as cosmicd has: state left by earlier inputs is part of what
  // is explored (a bound channel, then an unbind of it).
  static Harness* harness = new Harness();
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  // Privileged and unprivileged peers both reach the parser.
  const cosmic::PeerCredentials peer{1234, size % 2 == 0 ? 0u : 1000u, 0};
  const std::string answer = harness->protocol.handle(line, peer);
  // One line: the newline that ends it and no other.
  require(!answer.empty() && answer.find('\n') == answer.size() - 1);
  const auto json = nlohmann::json::parse(answer, nullptr, false);
  require(json.is_object() && json.contains("ok"));
  return 0;
}

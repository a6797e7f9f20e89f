// The YAML loaders: a whole configuration (cosmicd --config, cosmicctl check, reload) and a bind
// document (cosmicctl bind) read against a running configuration. Every input must end in a
// result or located errors, never an exception or a crash; every channel of a valid document
// must survive channel_to_yaml -> parse_channels unchanged (that is how bindings persist).
#include <cstdint>
#include <string_view>

#include "cosmic/config_loader.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

const cosmic::Config& running_config() {
  static const cosmic::Config config = cosmic::parse_config(R"(
segments:
  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}
  - {name: lan, type: dds, domain: 0}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7667?ttl=0"}
channels: []
)",
                                                            "running.yaml")
                                           .config;
  return config;
}

void check_errors(const std::vector<cosmic::ConfigError>& errors) {
  for (const auto& e : errors) {
    require(!e.message.empty());
    require(e.line >= 0 && e.column >= 0);
  }
}

void check_round_trip(const cosmic::ChannelSpec& channel, const cosmic::Config& segments) {
  const auto again = cosmic::parse_channels(cosmic::channel_to_yaml(channel), "round-trip.yaml", segments);
  require(again.ok() && again.channels.size() == 1 && again.channels.front() == channel);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  const cosmic::ConfigResult config = cosmic::parse_config(text, "fuzz.yaml");
  check_errors(config.errors);
  if (config.ok()) {
    for (const auto& channel : config.config.channels) check_round_trip(channel, config.config);
  }

  const cosmic::ChannelsResult bind = cosmic::parse_channels(text, "bind.yaml", running_config());
  check_errors(bind.errors);
  if (bind.ok()) {
    require(!bind.channels.empty());
    for (const auto& channel : bind.channels) check_round_trip(channel, running_config());
  }
  return 0;
}

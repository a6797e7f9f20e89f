// cosmicd's state file (runtime bindings), as it is read at start: any content must load as a
// state or one error, never crash; a loaded state saved again loads back equal; every entry's
// definition goes through the same checks cosmicd applies before binding it.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "binding_store.hpp"
#include "cosmic/config_loader.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

namespace {

const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("cosmic-fuzz-state-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

const cosmic::Config& running_config() {
  static const cosmic::Config config = cosmic::parse_config(R"(
segments:
  - {name: lan, type: dds, domain: 0}
  - {name: viz, type: lcm}
channels: []
)",
                                                            "running.yaml")
                                           .config;
  return config;
}

bool same(const cosmicd::BindingState& a, const cosmicd::BindingState& b) {
  if (a.unbound != b.unbound || a.bound.size() != b.bound.size()) return false;
  for (std::size_t i = 0; i < a.bound.size(); ++i) {
    if (a.bound[i].name != b.bound[i].name || a.bound[i].yaml != b.bound[i].yaml) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input = (scratch_dir() / "input.json").string();
  const std::string saved = (scratch_dir() / "saved.json").string();
  if (std::FILE* f = std::fopen(input.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  const cosmicd::LoadedState loaded = cosmicd::load_binding_state(input);
  if (!loaded.error.empty()) return 0;
  for (const auto& entry : loaded.state.bound) {
    const auto channels = cosmic::parse_channels(entry.yaml, "state.json", running_config());
    if (channels.ok()) cosmicd::check_binding_entry(entry, channels.channels);
  }
  require(cosmicd::save_binding_state(saved, loaded.state).empty());
  const cosmicd::LoadedState again = cosmicd::load_binding_state(saved);
  require(again.error.empty() && same(again.state, loaded.state));
  return 0;
}

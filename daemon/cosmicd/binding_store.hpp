// Runtime changes that must survive a restart: channels bound and configuration channels unbound
// through the control socket. Kept in a versioned JSON file in the state directory, written
// atomically (temporary file, fsync, rename, fsync of the directory).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace cosmicd {

struct RuntimeBinding {
  std::string name;  // channel name
  std::string yaml;  // its definition (cosmic::channel_to_yaml)
};

struct BindingState {
  static constexpr int kVersion = 1;
  std::vector<RuntimeBinding> bound;
  std::vector<std::string> unbound;  // channels of the configuration file unbound at run time
};

struct LoadedState {
  BindingState state;
  std::string error;  // set when the file exists but cannot be used
};

// A missing file is an empty state, not an error.
LoadedState load_binding_state(const std::string& path);
// Empty string on success, else why it failed (the previous file is then untouched).
std::string save_binding_state(const std::string& path, const BindingState& state);

}  // namespace cosmicd

// Runtime changes that must survive a restart: channels bound and configuration channels unbound
// through the control socket. Kept in a versioned JSON file in the state directory, written
// atomically (a fresh temporary file created with O_EXCL|O_NOFOLLOW, fsync, rename, fsync of the
// directory). Loading reads regular files only, up to kMaxStateFileBytes, and never blocks.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmicd {

inline constexpr std::size_t kMaxStateFileBytes = 16u << 20;

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

// A missing file is an empty state, not an error. Anything but a regular file (a FIFO, a
// device such as /dev/zero, a directory) and a file above kMaxStateFileBytes are errors.
LoadedState load_binding_state(const std::string& path);
// Empty string on success, else why it failed (the previous file is then untouched).
std::string save_binding_state(const std::string& path, const BindingState& state);

// A state file that exists but cannot be used is renamed to "<path>.corrupt-<N>" (the first N
// from 1 that is free), so the next save cannot overwrite the runtime bindings it may still hold.
// Nothing at `path` (e.g. its directory is missing or not a directory): nothing moved, no error.
struct SetAside {
  std::string moved_to;  // the new name, when it was moved
  std::string error;     // why it could not be moved
};
SetAside set_aside_state_file(const std::string& path);

}  // namespace cosmicd

namespace cosmicd {
// Empty when `channels` (the entry's YAML, parsed) define exactly the channel the entry is
// named after; else why the entry cannot be trusted (it would come back after an unbind).
std::string check_binding_entry(const RuntimeBinding& entry, const std::vector<cosmic::ChannelSpec>& channels);
}  // namespace cosmicd

// Reading the key files a configuration names (an LCM segment's `auth: {key_file}`, issue 36):
// relative to the configuration's own file, a regular file only its owner may read or write,
// holding the key as hexadecimal digits (cosmic/secret_key.hpp). Every problem is reported at
// the `key_file` value, never quoting the file's content. Internal to the config library.
#pragma once

#include <sys/stat.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "cosmic/secret_key.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Why a file of this status must not hold secrets: group or others may read or write it, or it
// belongs to another user than this process's or root (who could change it under us). Empty: fine.
std::string refuse_unless_private(const struct stat& status);

struct LoadedKey {
  std::string path;  // as resolved against the configuration's directory
  SecretKey key;
};

// The key in the file `node` names (key path `path`), of `min_bytes` to `max_bytes` bytes; its
// resolved path goes to `included`. Nullopt after reporting why not.
std::optional<LoadedKey> load_key_file(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                       std::vector<std::string>& included, std::size_t min_bytes,
                                       std::size_t max_bytes);

// An LCM segment's `auth: {key_file, accept_key_files, window, cost}` (cosmic/lcm_auth.hpp), every
// problem reported at its key; the key files read go to `included`.
LcmAuthSpec parse_lcm_auth(YamlReader& reader, const YAML::Node& node, const std::string& path,
                           std::vector<std::string>& included);

}  // namespace cosmic::config_detail

// Reading a DBC file a configuration names (a CAN bus's background traffic, a typed channel's
// `type: {dbc: FILE, message: NAME}`): relative to the configuration's own file, a regular file of
// at most kDbcMaxTextBytes read without blocking on a FIFO or a device, its errors reported located
// in the DBC file itself. Internal to the config library; runs where the configuration is loaded.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cosmic/dbc.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

struct LoadedDbc {
  std::string path;  // as resolved against the configuration's directory
  DbcFile file;      // without errors
};

// `where` is the YAML value that names `file`, `key_path` its key path; every problem goes to
// `reader`, and the resolved path of a file read to `included` (ConfigResult::included_files).
std::optional<LoadedDbc> load_dbc_file(YamlReader& reader, const YAML::Node& where, const std::string& key_path,
                                       const std::string& file, std::vector<std::string>& included);

}  // namespace cosmic::config_detail

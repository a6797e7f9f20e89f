// Reading the type files a configuration names (a CAN bus's background traffic from a DBC file, a
// typed channel's `type: {dbc: FILE, ...}` or `{lcm: FILE, ...}`): relative to the configuration's
// own file, a regular file of bounded size read without blocking on a FIFO or a device, its errors
// reported located in that file itself. Internal to the config library; runs where the
// configuration is loaded.
#pragma once

#include <sys/stat.h>

#include <optional>
#include <string>
#include <vector>

#include "cosmic/dbc.hpp"
#include "cosmic/e2e_protection.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// Reads a regular file of at most `max_bytes` into `text` without ever blocking on a FIFO or a
// device; why not, or an empty string. `refuse`, where given, says why a file of that status
// (owner, permissions) must not be read (empty: it may).
std::string read_regular_file(const std::string& path, std::string& text, std::size_t max_bytes,
                              std::string (*refuse)(const struct stat& status) = nullptr);

struct LoadedText {
  std::string path;  // as resolved against the configuration's directory
  std::string text;
};

// The text of `file` (at most `max_bytes`), or nullopt after reporting why not at `where`; `what`
// names the kind of file in the message ("DBC file", "LCM type file").
std::optional<LoadedText> load_named_file(YamlReader& reader, const YAML::Node& where, const std::string& key_path,
                                          const std::string& file, std::vector<std::string>& included,
                                          std::size_t max_bytes, const std::string& what);

struct LoadedDbc {
  std::string path;  // as resolved against the configuration's directory
  DbcFile file;      // without errors
};

// `where` is the YAML value that names `file`, `key_path` its key path; every problem goes to
// `reader`, and the resolved path of a file read to `included` (ConfigResult::included_files).
std::optional<LoadedDbc> load_dbc_file(YamlReader& reader, const YAML::Node& where, const std::string& key_path,
                                       const std::string& file, std::vector<std::string>& included);

// A DBC message's end-to-end protection: `e2e: {counter: SIG, crc: SIG, data_id: N, data_id_mode:
// both|low|alt}` (cosmic/e2e_protection.hpp), checked against `message`; nullopt after reporting.
std::optional<E2eSpec> parse_e2e(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                 const DbcMessage& message);

}  // namespace cosmic::config_detail

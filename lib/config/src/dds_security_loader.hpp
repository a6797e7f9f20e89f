// A DDS segment's `security: {identity_ca, certificate, private_key, permissions_ca, governance,
// permissions}` (issue 36; docs/security.md): the six files, relative to the configuration's own
// file, read and checked before any participant is made with them (cosmic/dds_security_files.hpp):
// each problem located at its key. Internal to the config library.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "cosmic/model.hpp"
#include "yaml_reader.hpp"

namespace cosmic::config_detail {

// The segment's security, or nullopt after reporting every problem; the files read go to `included`.
// With `documents_pending` the governance and permissions files are not read (they are about to be
// written, LoadOptions): only their paths are resolved.
std::optional<DdsSecuritySpec> parse_dds_security(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                                  std::vector<std::string>& included, bool documents_pending = false);

}  // namespace cosmic::config_detail

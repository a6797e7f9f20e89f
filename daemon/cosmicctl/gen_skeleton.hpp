// Code generation from the Event-Channel Diagram (Kaiser et al., Fig. 8): the C++ skeleton of one
// component on libcosmic-client. Pure text building; gen_command.cpp writes the files.
//
// Files (NAME = the component, Class = NAME in CamelCase):
//   CMakeLists.txt     the project; finds libcosmic-client (cosmic_client-config.cmake)
//   channels.hpp       the channel configuration from the model (cosmic_channel_desc per channel)
//   NAME.hpp, NAME.cpp the component class: announces its channels, one handler per subscribed
//                      channel (refresh_CHANNEL), one periodic handler per published channel with
//                      a period (CHANNEL_period), run loop; handlers never run at the same time
//   NAME_logic.cpp     the handlers' bodies and the component's State: the user's file
//   main.cpp           options (--segment, --check SOCKET), signals, run
#pragma once

#include <map>
#include <optional>
#include <string>

#include "cosmic/model.hpp"
#include "cosmic/result.hpp"

namespace cosmicctl {

struct Skeleton {
  std::map<std::string, std::string> files;  // file name -> content
  std::string logic_file;                    // the one file the user edits
};

// `client_config_dir`: where cosmic_client-config.cmake lives (a hint; -Dcosmic_client_DIR wins).
Skeleton generate_skeleton(const cosmic::Config& config, const cosmic::ComponentSpec& component,
                           const std::string& model_file, const std::string& client_config_dir);

// Why `component`'s skeleton cannot be generated: two of its channels whose names differ only
// in '-', '.' or '_' would become one C++ identifier (issue 22, item 5). nullopt when none.
cosmic::Result<void> check_identifiers(const cosmic::Config& config, const cosmic::ComponentSpec& component);

}  // namespace cosmicctl

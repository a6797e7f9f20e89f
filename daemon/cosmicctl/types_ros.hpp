// `cosmicctl types` for ROS 2 and OMG IDL type files (types_ros.cpp): what an IDL file (.idl) or a
// ROS 2 message (.msg) defines, as a typed channel (type: {idl|msg: FILE, name: ...}) would see it,
// the files it refers to found as the configuration finds them (cosmic/ros_type_files.hpp).
// Offline; called on cosmicctl's one thread.
#pragma once

#include <string>
#include <vector>

#include "commands.hpp"

namespace cosmicctl {

struct RosTypesRequest {
  std::string file;                    // as given
  std::string text;                    // its contents
  std::vector<std::string> type_path;  // --type-path, in order
  std::string name;                    // --name pkg/msg/Name (.msg; else from FILE's path)
};

int run_idl_types(const RosTypesRequest& request, const GlobalOptions& global);
int run_msg_types(const RosTypesRequest& request, const GlobalOptions& global);

}  // namespace cosmicctl

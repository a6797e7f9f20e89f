// Where the files an IDL file #includes and the messages a ROS 2 .msg file refers to are found,
// the same for the configuration (`type: {idl|msg: FILE, type_path: [...]}`) and for tools
// (`cosmicctl types FILE --type-path DIR`): the type_path directories in order, then FILE's own
// directory, then ROOT when FILE lies at ROOT/pkg/msg/Name.* (as ROS 2 installs its messages).
// Reads regular files only, of bounded size, never blocking on a FIFO or a device. Any thread.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace cosmic {

std::vector<std::string> ros_type_roots(const std::string& file, const std::vector<std::string>& type_path);

// The text of the first root's `relative` path that reads as a regular file of at most
// `max_bytes`; its path is appended to `read`.
std::optional<std::string> read_from_roots(const std::vector<std::string>& roots, const std::string& relative,
                                           std::size_t max_bytes, std::vector<std::string>& read);

}  // namespace cosmic

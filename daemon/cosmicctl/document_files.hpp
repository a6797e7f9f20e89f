// Writing several generated documents all or nothing (`cosmicctl security permissions`): each is
// written to a temporary file in its own directory first, mode 0644, flushed to disk; only when
// every one is written are they renamed into place, so a failure (a directory that does not exist
// or cannot be written) leaves every existing file as it was. Called from the command's thread.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace cosmicctl {

struct DocumentFile {
  std::string path;
  std::string content;
};

struct WriteFailure {
  std::string message;             // names the file and the reason
  bool permission_denied = false;  // EACCES, EPERM or EROFS
};

// Writes `files`; nullopt when every one is in place.
std::optional<WriteFailure> write_documents(const std::vector<DocumentFile>& files);

}  // namespace cosmicctl

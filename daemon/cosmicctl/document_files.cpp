// All-or-nothing writing of generated documents (document_files.hpp).
#include "document_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace cosmicctl {
namespace {

WriteFailure failure_of(const std::string& what, const std::string& path, int error) {
  return {"cannot " + what + " " + path + ": " + std::strerror(error),
          error == EACCES || error == EPERM || error == EROFS};
}

// `content` in a new temporary file next to `path`; its name, or the failure.
std::optional<WriteFailure> write_temporary(const std::string& path, const std::string& content,
                                            std::string& temporary) {
  const std::filesystem::path target(path);
  std::string pattern = (target.parent_path() / ("." + target.filename().string() + ".XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0) return failure_of("write", path, errno);
  temporary = pattern;
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = errno;
      ::close(fd);
      return failure_of("write", path, error);
    }
    written += static_cast<std::size_t>(n);
  }
  // Public documents: every participant's user reads them (mkstemp made it 0600).
  if (::fchmod(fd, 0644) != 0 || ::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    return failure_of("write", path, error);
  }
  if (::close(fd) != 0) return failure_of("write", path, errno);
  return std::nullopt;
}

}  // namespace

std::optional<WriteFailure> write_documents(const std::vector<DocumentFile>& files) {
  std::vector<std::string> temporaries;
  auto discard = [&temporaries] {
    for (const auto& t : temporaries) ::unlink(t.c_str());
  };
  for (const DocumentFile& file : files) {
    std::string temporary;
    auto failure = write_temporary(file.path, file.content, temporary);
    if (!temporary.empty()) temporaries.push_back(temporary);
    if (failure) {
      discard();
      failure->message += "; no document was changed";
      return failure;
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (::rename(temporaries[i].c_str(), files[i].path.c_str()) != 0) {
      // Only a file system gone wrong fails here (same directory, file just written).
      auto failure = failure_of("replace", files[i].path, errno);
      temporaries.erase(temporaries.begin(), temporaries.begin() + static_cast<std::ptrdiff_t>(i));
      discard();
      failure.message += " (the documents before it in this list are already replaced)";
      return failure;
    }
  }
  return std::nullopt;
}

}  // namespace cosmicctl

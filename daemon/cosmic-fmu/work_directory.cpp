#include "work_directory.hpp"

#include <cerrno>
#include <cstdlib>
#include <system_error>
#include <vector>

namespace cosmic_fmu {

cosmic::Result<WorkDirectory> WorkDirectory::make(const std::string& parent, const std::string& name) {
  std::string pattern = parent + "/cosmic-fmu-" + name + "-XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr)
    return cosmic::Error::from_errno("cannot make a work directory " + pattern, errno);
  return WorkDirectory(std::string(buffer.data()));
}

WorkDirectory::~WorkDirectory() {
  if (path_.empty()) return;
  std::error_code ignored;  // nothing to do about a directory that will not go at exit
  std::filesystem::remove_all(path_, ignored);
}

}  // namespace cosmic_fmu

// A private directory for the extracted FMU (cosmic-fmu): made with mkdtemp(3) below `parent`,
// mode 0700, removed with everything in it when this goes. Never throws after construction.
#pragma once

#include <filesystem>
#include <string>

#include "cosmic/result.hpp"

namespace cosmic_fmu {

class WorkDirectory {
 public:
  static cosmic::Result<WorkDirectory> make(const std::string& parent, const std::string& name);
  WorkDirectory(WorkDirectory&& other) noexcept : path_(std::exchange(other.path_, {})) {}
  WorkDirectory& operator=(WorkDirectory&&) = delete;
  WorkDirectory(const WorkDirectory&) = delete;
  ~WorkDirectory();
  const std::string& path() const { return path_; }

 private:
  explicit WorkDirectory(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

}  // namespace cosmic_fmu

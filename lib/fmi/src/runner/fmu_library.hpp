// What the FMI 2.0 and 3.0 instances share: the dlopen()ed library and its functions looked up by
// name (internal to cosmic_fmu_runner).
#pragma once

#include <dlfcn.h>

#include <memory>
#include <string>

#include "cosmic/fmu_instance.hpp"

namespace cosmic::fmi::runner_detail {

// The FMU's shared library, loaded RTLD_NOW | RTLD_LOCAL (its symbols stay its own, so two FMUs
// exporting the same fmi2DoStep do not meet) and closed when the last owner goes.
class SharedLibrary {
 public:
  static Result<std::shared_ptr<SharedLibrary>> open(const std::string& path);
  ~SharedLibrary();
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  // The function `name` as a pointer to `Function` (a function type of fmi2_api.h / fmi3_api.h),
  // or an error naming it.
  template <typename Function>
  Result<Function*> function(const char* name) const {
    void* address = ::dlsym(handle_, name);
    if (address == nullptr) return Error{path_ + " does not export " + name + " (an FMI function co-simulation needs)"};
    return reinterpret_cast<Function*>(address);
  }
  const std::string& path() const { return path_; }

 private:
  SharedLibrary(void* handle, std::string path) : handle_(handle), path_(std::move(path)) {}
  void* handle_;
  std::string path_;
};

// "file:///dir/with%20space/resources": an FMI 2.0 resource location (RFC 3986; unreserved
// characters and '/' kept, the rest percent-encoded).
std::string file_uri(const std::string& absolute_path);

Result<std::unique_ptr<FmuInstance>> instantiate_fmi2(std::shared_ptr<SharedLibrary> library, const OpenedFmu& fmu,
                                                      const InstanceOptions& options);
Result<std::unique_ptr<FmuInstance>> instantiate_fmi3(std::shared_ptr<SharedLibrary> library, const OpenedFmu& fmu,
                                                      const InstanceOptions& options);

}  // namespace cosmic::fmi::runner_detail

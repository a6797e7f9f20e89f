// Loading an FMU's library and what every instance shares (cosmic/fmu_instance.hpp).
#include "cosmic/fmu_instance.hpp"

#include "fmu_library.hpp"

namespace cosmic::fmi {

namespace runner_detail {

Result<std::shared_ptr<SharedLibrary>> SharedLibrary::open(const std::string& path) {
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = ::dlerror();
    return Error{"cannot load the FMU's binary " + path + ": " + (why ? why : "dlopen failed")};
  }
  return std::shared_ptr<SharedLibrary>(new SharedLibrary(handle, path));
}

SharedLibrary::~SharedLibrary() { ::dlclose(handle_); }

std::string file_uri(const std::string& absolute_path) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out = "file://";
  for (const char c : absolute_path) {
    const auto u = static_cast<unsigned char>(c);
    const bool kept = (u >= 'a' && u <= 'z') || (u >= 'A' && u <= 'Z') || (u >= '0' && u <= '9') || u == '-' ||
                      u == '.' || u == '_' || u == '~' || u == '/';
    if (kept) {
      out += c;
    } else {
      out += '%';
      out += kHex[u >> 4];
      out += kHex[u & 15];
    }
  }
  return out;
}

}  // namespace runner_detail

std::string FmuInstance::recent_log_text() const {
  std::string out;
  for (const auto& line : log_) out += "[" + line.status + "] " + line.category + ": " + line.message + "\n";
  return out;
}

std::string FmuInstance::last_words() const {
  return log_.empty() ? std::string(" (the FMU logged nothing)") : "; the FMU said: " + log_.back().message;
}

void FmuInstance::keep_log(FmuLogLine line) {
  if (line.message.size() > kMaxLogLineBytes) line.message.resize(kMaxLogLineBytes);
  if (log_.size() == kMaxKeptLogLines) log_.pop_front();
  log_.push_back(std::move(line));
}

Result<std::unique_ptr<FmuInstance>> instantiate(const OpenedFmu& fmu, const InstanceOptions& options) {
  auto library = runner_detail::SharedLibrary::open(fmu.binary);
  if (!library) return library.error();
  if (fmu.description.version == FmiVersion::fmi2)
    return runner_detail::instantiate_fmi2(std::move(library.value()), fmu, options);
  return runner_detail::instantiate_fmi3(std::move(library.value()), fmu, options);
}

}  // namespace cosmic::fmi

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

namespace {

// `text` as valid UTF-8 of at most `limit` bytes: a byte that does not start a well-formed sequence
// (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF) becomes '?', and a character the
// limit would cut is left out.
std::string valid_utf8(const std::string& text, std::size_t limit) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b = static_cast<unsigned char>(text[i]);
    const std::size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    bool sound = n != 0 && i + n <= text.size();
    for (std::size_t k = 1; sound && k < n; ++k) sound = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (sound && n > 1) {
      const auto c1 = static_cast<unsigned char>(text[i + 1]);
      sound = !(n == 2 && b < 0xC2) && !(n == 3 && b == 0xE0 && c1 < 0xA0) && !(n == 3 && b == 0xED && c1 >= 0xA0) &&
              !(n == 4 && b == 0xF0 && c1 < 0x90) && !(n == 4 && (b > 0xF4 || (b == 0xF4 && c1 >= 0x90)));
    }
    const std::size_t take = sound ? n : 1;
    if (out.size() + take > limit) break;
    if (sound) {
      out.append(text, i, n);
    } else {
      out += '?';
    }
    i += take;
  }
  return out;
}

}  // namespace

void FmuInstance::keep_log(FmuLogLine line) noexcept {
  try {
    line.status = valid_utf8(line.status, 16);
    line.category = valid_utf8(line.category, 128);
    line.message = valid_utf8(line.message, kMaxLogLineBytes);
    if (log_.size() == kMaxKeptLogLines) log_.pop_front();
    log_.push_back(std::move(line));
  } catch (...) {  // out of memory inside the FMU's logger call: the message is lost, not the FMU
  }
}

Result<std::unique_ptr<FmuInstance>> instantiate(const OpenedFmu& fmu, const InstanceOptions& options) {
  auto library = runner_detail::SharedLibrary::open(fmu.binary);
  if (!library) return library.error();
  if (fmu.description.version == FmiVersion::fmi2)
    return runner_detail::instantiate_fmi2(std::move(library.value()), fmu, options);
  return runner_detail::instantiate_fmi3(std::move(library.value()), fmu, options);
}

}  // namespace cosmic::fmi

// An FMU's zip archive read and extracted (cosmic/fmu_archive.hpp).
#include "cosmic/fmu_archive.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zip.h>

#include <cerrno>

#include <filesystem>
#include <memory>
#include <optional>
#include <set>

#include "cosmic/result.hpp"

namespace cosmic::fmi {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kDescriptionEntry = "modelDescription.xml";
constexpr std::string_view kBinaries = "binaries/";
constexpr std::string_view kResources = "resources/";

struct ZipCloser {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* file) const { zip_fclose(file); }
};

std::string zip_error_text(int code) {
  zip_error_t error;
  zip_error_init_with_code(&error, code);
  std::string text = zip_error_strerror(&error);
  zip_error_fini(&error);
  return text;
}

// An open archive whose entries were checked: safe names, no links, a bounded count.
class Archive {
 public:
  explicit Archive(std::string path) : path_(std::move(path)) {}

  bool open(std::vector<std::string>& errors) {
    // A regular file only, said plainly (libzip answers "Operation not supported" for a FIFO).
    struct stat file_stat {};
    if (::stat(path_.c_str(), &file_stat) != 0) {
      errors.push_back("cannot open " + path_ + ": " + errno_text(errno));
      return false;
    }
    if (!S_ISREG(file_stat.st_mode)) {
      errors.push_back(path_ + " is not an FMU: not a regular file");
      return false;
    }
    int code = 0;
    zip_.reset(zip_open(path_.c_str(), ZIP_RDONLY, &code));
    if (!zip_) {
      errors.push_back(code == ZIP_ER_NOZIP ? path_ + " is not an FMU: not a zip archive"
                                            : "cannot open " + path_ + ": " + zip_error_text(code));
      return false;
    }
    const zip_int64_t count = zip_get_num_entries(zip_.get(), 0);
    if (count < 0 || static_cast<std::uint64_t>(count) > kMaxArchiveEntries) {
      errors.push_back(path_ + " has more than " + std::to_string(kMaxArchiveEntries) + " entries");
      return false;
    }
    for (zip_uint64_t i = 0; i < static_cast<zip_uint64_t>(count); ++i) {
      const char* name = zip_get_name(zip_.get(), i, ZIP_FL_ENC_RAW);
      if (name == nullptr) continue;
      if (!safe_entry_name(name)) {
        errors.push_back(path_ + ": entry '" + std::string(name) +
                         "' would leave the directory it is extracted to (an absolute path, '..' or '\\')");
        return false;
      }
      if (is_link(i)) {
        errors.push_back(path_ + ": entry '" + std::string(name) + "' is a symbolic link");
        return false;
      }
      names_.push_back(name);
    }
    return true;
  }

  const std::vector<std::string>& names() const { return names_; }

  std::optional<zip_uint64_t> find(std::string_view name) const {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return static_cast<zip_uint64_t>(i);
    return std::nullopt;
  }

  // The entry's bytes, at most `limit`; sink(bytes) takes them in pieces. Empty string or why not.
  template <typename Sink>
  std::string read(zip_uint64_t index, std::uint64_t limit, Sink&& sink) {
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(zip_.get(), index, 0, &stat) != 0 || (stat.valid & ZIP_STAT_SIZE) == 0)
      return "cannot read the size of " + names_[index];
    if (stat.size > limit)
      return names_[index] + " has " + std::to_string(stat.size) + " bytes, more than " + std::to_string(limit) +
             " allowed";
    std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(zip_.get(), index, 0));
    if (!file) return "cannot read " + names_[index] + ": " + zip_strerror(zip_.get());
    char buffer[1 << 16];
    std::uint64_t total = 0;
    for (;;) {
      const zip_int64_t n = zip_fread(file.get(), buffer, sizeof buffer);
      if (n < 0) return "cannot read " + names_[index] + ": " + zip_file_strerror(file.get());
      if (n == 0) break;
      total += static_cast<std::uint64_t>(n);
      if (total > stat.size) return names_[index] + " holds more bytes than its header says";
      if (auto why = sink(std::string_view(buffer, static_cast<std::size_t>(n))); !why.empty()) return why;
    }
    return {};
  }

  const std::string& path() const { return path_; }

 private:
  bool is_link(zip_uint64_t index) const {
    zip_uint8_t system = 0;
    zip_uint32_t attributes = 0;
    if (zip_file_get_external_attributes(zip_.get(), index, 0, &system, &attributes) != 0) return false;
    return system == ZIP_OPSYS_UNIX && S_ISLNK(static_cast<mode_t>(attributes >> 16));
  }

  std::string path_;
  std::unique_ptr<zip_t, ZipCloser> zip_;
  std::vector<std::string> names_;
};

// The platforms the archive has binaries for: the directories right below binaries/.
std::string platforms_of(const std::vector<std::string>& names) {
  std::set<std::string> platforms;
  for (const auto& n : names) {
    if (!n.starts_with(kBinaries)) continue;
    const std::string rest = n.substr(kBinaries.size());
    const auto slash = rest.find('/');
    if (slash != std::string::npos && slash > 0) platforms.insert(rest.substr(0, slash));
  }
  std::string out;
  for (const auto& p : platforms) out += (out.empty() ? "" : ", ") + p;
  return out.empty() ? "none (no binaries/ directory: a source-only FMU is not built by cosmic-fmu)" : out;
}

bool read_contents(Archive& archive, FmuContents& contents, std::vector<std::string>& errors) {
  if (!archive.open(errors)) return false;
  const auto index = archive.find(kDescriptionEntry);
  if (!index) {
    errors.push_back(archive.path() + " is not an FMU: it holds no modelDescription.xml");
    return false;
  }
  std::string xml;
  const std::string why = archive.read(*index, kMaxDescriptionBytes, [&](std::string_view bytes) {
    xml.append(bytes);
    return std::string();
  });
  if (!why.empty()) {
    errors.push_back(archive.path() + ": " + why);
    return false;
  }
  DescriptionResult parsed = parse_model_description(xml);
  for (const auto& p : parsed.problems) errors.push_back(archive.path() + ": " + p.to_string());
  if (!parsed.ok()) return false;
  contents.description = std::move(parsed.description);
  const std::string_view platform = platform_directory(contents.description.version);
  contents.binary_entry = std::string(kBinaries) + std::string(platform) + "/" +
                          contents.description.co_simulation->model_identifier + ".so";
  if (platform.empty() || !archive.find(contents.binary_entry)) {
    errors.push_back(archive.path() + " has no binary for this platform (" +
                     (platform.empty() ? std::string("FMI 2.0 names none for it") : contents.binary_entry) +
                     "); its platforms: " + platforms_of(archive.names()));
    return false;
  }
  return true;
}

// Writes one entry below `root`; never follows or replaces what is there.
std::string extract(Archive& archive, zip_uint64_t index, const fs::path& root, std::uint64_t& budget) {
  const std::string& name = archive.names()[index];
  const fs::path target = root / name;
  std::error_code ec;
  if (name.ends_with('/')) {
    fs::create_directories(target, ec);
    return ec ? "cannot create " + target.string() + ": " + ec.message() : std::string();
  }
  fs::create_directories(target.parent_path(), ec);
  if (ec) return "cannot create " + target.parent_path().string() + ": " + ec.message();
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) return "cannot create " + target.string() + ": " + errno_text(errno);
  std::string why = archive.read(index, budget, [&](std::string_view bytes) {
    for (std::size_t done = 0; done < bytes.size();) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return "cannot write " + target.string() + ": " + errno_text(errno);
      done += static_cast<std::size_t>(n);
    }
    budget -= bytes.size();
    return std::string();
  });
  if (::close(fd) != 0 && why.empty()) why = "cannot write " + target.string() + ": " + errno_text(errno);
  return why;
}

}  // namespace

std::string_view platform_directory(FmiVersion version) {
#if defined(__x86_64__)
  return version == FmiVersion::fmi2 ? "linux64" : "x86_64-linux";
#elif defined(__aarch64__)
  return version == FmiVersion::fmi2 ? "" : "aarch64-linux";
#else
#error "platform_directory: no FMI platform name for this architecture"
#endif
}

bool safe_entry_name(std::string_view name) {
  if (name.empty() || name.front() == '/' || name.find('\\') != std::string_view::npos ||
      name.find('\0') != std::string_view::npos)
    return false;
  for (std::size_t start = 0; start <= name.size();) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    if (name.substr(start, end - start) == "..") return false;
    start = end + 1;
  }
  return true;
}

FmuReadResult read_fmu(const std::string& path) {
  FmuReadResult result;
  Archive archive(path);
  read_contents(archive, result.contents, result.errors);
  return result;
}

FmuOpenResult open_fmu(const std::string& path, const std::string& work_dir) {
  FmuOpenResult result;
  Archive archive(path);
  FmuContents contents;
  if (!read_contents(archive, contents, result.errors)) return result;
  const fs::path root = fs::absolute(work_dir);
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec || !fs::is_empty(root, ec)) {
    result.errors.push_back("cannot extract " + path + " into " + root.string() + ": " +
                            (ec ? ec.message() : std::string("the directory is not empty")));
    return result;
  }
  const std::string platform_prefix =
      std::string(kBinaries) + std::string(platform_directory(contents.description.version)) + "/";
  std::uint64_t budget = kMaxExtractedBytes;
  for (zip_uint64_t i = 0; i < archive.names().size(); ++i) {
    const std::string& name = archive.names()[i];
    if (!name.starts_with(platform_prefix) && !name.starts_with(kResources)) continue;
    if (auto why = extract(archive, i, root, budget); !why.empty()) {
      result.errors.push_back(path + ": " + why);
      return result;
    }
  }
  fs::create_directories(root / "resources", ec);
  result.fmu.description = std::move(contents.description);
  result.fmu.binary = (root / contents.binary_entry).string();
  result.fmu.resources = (root / "resources").string();
  return result;
}

}  // namespace cosmic::fmi

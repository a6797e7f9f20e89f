#include "binding_store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

namespace cosmicd {
namespace {

using Json = nlohmann::json;

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

bool write_all(int fd, const std::string& data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

// Reads an open state file into `out`, or says why not.
std::string read_regular_file(int fd, const std::string& path, std::string& out) {
  struct stat info {};
  if (::fstat(fd, &info) != 0) return errno_text("cannot stat " + path);
  if (!S_ISREG(info.st_mode)) return path + ": not a regular file; refusing to read it";
  if (static_cast<std::uint64_t>(info.st_size) > kMaxStateFileBytes) {
    return path + ": " + std::to_string(info.st_size) + " bytes, above the limit of " +
           std::to_string(kMaxStateFileBytes);
  }
  char buffer[65536];
  while (true) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return errno_text("cannot read " + path);
    if (n == 0) return {};
    out.append(buffer, static_cast<std::size_t>(n));
    if (out.size() > kMaxStateFileBytes)
      return path + ": grew above the limit of " + std::to_string(kMaxStateFileBytes) + " bytes";
  }
}

// O_NONBLOCK: opening a FIFO must not wait for a writer; the type check then refuses it before
// any read.
std::string read_state_file(const std::string& path, std::string& out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return errno_text("cannot open " + path);
  std::string error = read_regular_file(fd, path, out);
  ::close(fd);
  return error;
}

// A name nobody can predict, created exclusively: a symlink or file planted in the state
// directory is never followed or overwritten.
int create_temporary(const std::string& path, std::string& temporary) {
  static std::atomic<std::uint64_t> counter{0};
  std::random_device random;
  for (int attempt = 0; attempt < 16; ++attempt) {
    temporary =
        path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++) + "." + std::to_string(random());
    const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0640);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  return -1;
}

}  // namespace

LoadedState load_binding_state(const std::string& path) {
  LoadedState out;
  struct stat info {};
  if (::lstat(path.c_str(), &info) != 0 && errno == ENOENT) return out;
  std::string text;
  if (std::string error = read_state_file(path, text); !error.empty()) {
    out.error = std::move(error);
    return out;
  }
  const Json doc = Json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) {
    out.error = path + ": not a JSON object (corrupted state file)";
    return out;
  }
  if (!doc.contains("version") || doc["version"] != BindingState::kVersion) {
    out.error = path + ": unsupported state version (expected " + std::to_string(BindingState::kVersion) + ")";
    return out;
  }
  try {
    for (const auto& b : doc.at("bound"))
      out.state.bound.push_back({b.at("name").get<std::string>(), b.at("yaml").get<std::string>()});
    for (const auto& u : doc.at("unbound")) out.state.unbound.push_back(u.get<std::string>());
  } catch (const Json::exception& e) {
    out.state = {};
    out.error = path + ": malformed state file: " + e.what();
  }
  return out;
}

SetAside set_aside_state_file(const std::string& path) {
  constexpr int kMaxAside = 1000;
  struct stat existing {};
  if (::lstat(path.c_str(), &existing) != 0) return SetAside{};  // nothing there to protect
  for (int n = 1; n <= kMaxAside; ++n) {
    const std::string target = path + ".corrupt-" + std::to_string(n);
    struct stat info {};
    if (::lstat(target.c_str(), &info) == 0 || errno != ENOENT) continue;
    // rename() would replace a file created in between; link() refuses to.
    if (::link(path.c_str(), target.c_str()) != 0) {
      if (errno == EEXIST) continue;
      return SetAside{"", errno_text("link " + path + " to " + target)};
    }
    if (::unlink(path.c_str()) != 0) return SetAside{"", errno_text("unlink " + path)};
    return SetAside{target, ""};
  }
  return SetAside{"", path + ": " + std::to_string(kMaxAside) + " set-aside copies exist already; remove old ones"};
}

std::string save_binding_state(const std::string& path, const BindingState& state) {
  Json doc{{"version", BindingState::kVersion}, {"bound", Json::array()}, {"unbound", state.unbound}};
  for (const auto& b : state.bound) doc["bound"].push_back({{"name", b.name}, {"yaml", b.yaml}});
  const std::filesystem::path target(path);
  std::error_code ec;
  std::filesystem::create_directories(target.parent_path(), ec);
  std::string temporary;
  const int fd = create_temporary(path, temporary);
  if (fd < 0) return errno_text("create a temporary file beside " + path);
  const bool written =
      write_all(fd, doc.dump(2, ' ', false, Json::error_handler_t::replace) + "\n") && ::fsync(fd) == 0;
  std::string write_error = written ? std::string() : errno_text("write " + temporary);
  ::close(fd);
  if (!written) {
    ::unlink(temporary.c_str());
    return write_error;
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    std::string error = errno_text("rename to " + path);
    ::unlink(temporary.c_str());
    return error;
  }
  const int dir =
      ::open(target.parent_path().empty() ? "." : target.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return {};
}

std::string check_binding_entry(const RuntimeBinding& entry, const std::vector<cosmic::ChannelSpec>& channels) {
  if (channels.size() == 1 && channels.front().name == entry.name) return {};
  std::string defined;
  for (const auto& c : channels) defined += (defined.empty() ? "" : ", ") + c.name;
  return "entry '" + entry.name + "' defines " +
         (channels.empty() ? std::string("no channel") : "channel(s) " + defined) +
         " instead of exactly the channel it is named after";
}

}  // namespace cosmicd

#include "binding_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

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

}  // namespace

LoadedState load_binding_state(const std::string& path) {
  LoadedState out;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return out;
  std::ifstream in(path);
  if (!in) {
    out.error = path + ": cannot be read";
    return out;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const Json doc = Json::parse(buffer.str(), nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) {
    out.error = path + ": not a JSON object (corrupted state file)";
    return out;
  }
  if (!doc.contains("version") || doc["version"] != BindingState::kVersion) {
    out.error = path + ": unsupported state version (expected " + std::to_string(BindingState::kVersion) + ")";
    return out;
  }
  try {
    for (const auto& b : doc.at("bound")) out.state.bound.push_back({b.at("name").get<std::string>(), b.at("yaml").get<std::string>()});
    for (const auto& u : doc.at("unbound")) out.state.unbound.push_back(u.get<std::string>());
  } catch (const Json::exception& e) {
    out.state = {};
    out.error = path + ": malformed state file: " + e.what();
  }
  return out;
}

std::string save_binding_state(const std::string& path, const BindingState& state) {
  Json doc{{"version", BindingState::kVersion}, {"bound", Json::array()}, {"unbound", state.unbound}};
  for (const auto& b : state.bound) doc["bound"].push_back({{"name", b.name}, {"yaml", b.yaml}});
  const std::filesystem::path target(path);
  std::error_code ec;
  std::filesystem::create_directories(target.parent_path(), ec);
  const std::string temporary = path + ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  if (fd < 0) return errno_text("open " + temporary);
  const bool written = write_all(fd, doc.dump(2) + "\n") && ::fsync(fd) == 0;
  ::close(fd);
  if (!written) {
    ::unlink(temporary.c_str());
    return errno_text("write " + temporary);
  }
  if (::rename(temporary.c_str(), path.c_str()) != 0) return errno_text("rename to " + path);
  const int dir = ::open(target.parent_path().empty() ? "." : target.parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return {};
}

}  // namespace cosmicd

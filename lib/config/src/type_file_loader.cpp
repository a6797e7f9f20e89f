// Reading the type files a configuration names (type_file_loader.hpp).
#include "type_file_loader.hpp"

#include "cosmic/e2e_protection.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>

namespace cosmic::config_detail {

std::string read_regular_file(const std::string& path, std::string& text, std::size_t max_bytes,
                              std::string (*refuse)(const struct stat& status)) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::strerror(errno);
  struct stat info {};
  std::string error;
  if (::fstat(fd, &info) != 0) {
    error = std::strerror(errno);
  } else if (!S_ISREG(info.st_mode)) {
    error = "not a regular file";
  } else if (refuse != nullptr && !(error = refuse(info)).empty()) {
    // refused for its permissions
  } else if (static_cast<std::uint64_t>(info.st_size) > max_bytes) {
    error = max_bytes >= (1u << 20) ? "larger than " + std::to_string(max_bytes >> 20) + " MiB"
                                    : "larger than " + std::to_string(max_bytes) + " bytes";
  } else {
    text.resize(static_cast<std::size_t>(info.st_size));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        error = std::strerror(errno);  // an I/O error is not the end of the file
        break;
      }
      if (n == 0) break;
      done += static_cast<std::size_t>(n);
    }
    text.resize(done);
  }
  ::close(fd);
  return error;
}

std::optional<LoadedText> load_named_file(YamlReader& reader, const YAML::Node& where, const std::string& key_path,
                                          const std::string& file, std::vector<std::string>& included,
                                          std::size_t max_bytes, const std::string& what) {
  const std::filesystem::path relative(file);
  const std::string resolved =
      relative.is_absolute()
          ? file
          : (std::filesystem::path(reader.file()).parent_path() / relative).lexically_normal().string();
  std::string text;
  if (const std::string error = read_regular_file(resolved, text, max_bytes); !error.empty()) {
    reader.error_at(where, key_path, "cannot read " + what + " " + resolved + ": " + error,
                    "a readable " + what + ", relative to this file");
    return std::nullopt;
  }
  included.push_back(resolved);
  return LoadedText{resolved, std::move(text)};
}

std::optional<LoadedDbc> load_dbc_file(YamlReader& reader, const YAML::Node& where, const std::string& key_path,
                                       const std::string& file, std::vector<std::string>& included) {
  const auto loaded = load_named_file(reader, where, key_path, file, included, kDbcMaxTextBytes, "DBC file");
  if (!loaded) return std::nullopt;
  DbcFile dbc = parse_dbc(loaded->text);
  for (const DbcError& e : dbc.errors)
    reader.error_in(ConfigError{loaded->path, e.line, e.column, key_path, e.message, ""});
  if (!dbc.ok()) return std::nullopt;
  return LoadedDbc{loaded->path, std::move(dbc)};
}

// e2e: {counter: SIG, crc: SIG, data_id: N, data_id_mode: both|low|alt} (cosmic/e2e_protection.hpp),
// checked against the message.
std::optional<E2eSpec> parse_e2e(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                 const DbcMessage& message) {
  if (!reader.check_map(node, path, {"counter", "crc", "data_id", "data_id_mode"})) return std::nullopt;
  const std::size_t errors_before = reader.error_count();
  for (const char* needed : {"counter", "crc", "data_id"}) {
    if (!has(node, needed))
      reader.error_at(node, path, std::string("end-to-end protection needs its ") + needed,
                      "e2e: {counter: SIGNAL, crc: SIGNAL, data_id: 0..0xFFFF}");
  }
  if (reader.error_count() != errors_before) return std::nullopt;
  E2eSpec spec;
  const auto counter = reader.string(node["counter"], key(path, "counter"));
  const auto crc = reader.string(node["crc"], key(path, "crc"));
  const auto data_id = reader.unsigned_int(node["data_id"], key(path, "data_id"), 0, 0xFFFF);
  std::optional<std::size_t> mode = 0;
  if (has(node, "data_id_mode"))
    mode = reader.choice(node["data_id_mode"], key(path, "data_id_mode"), {"both", "low", "alt"});
  if (!counter || !crc || !data_id || !mode) return std::nullopt;
  spec = E2eSpec{*counter, *crc, static_cast<std::uint16_t>(*data_id), static_cast<E2eDataIdMode>(*mode)};
  if (Result<E2eProtection> checked = E2eProtection::make(message, spec); !checked) {
    reader.error_at(node, path, checked.error().text);
    return std::nullopt;
  }
  return spec;
}

}  // namespace cosmic::config_detail

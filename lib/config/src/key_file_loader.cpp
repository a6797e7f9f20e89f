// Reading key files (key_file_loader.hpp).
#include "key_file_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include "cosmic/key_file.hpp"
#include "cosmic/lcm_auth_layout.hpp"
#include "type_file_loader.hpp"

namespace cosmic {
namespace {

constexpr std::size_t kMaxKeyFileBytes = 4096;  // a key of 64 bytes is 128 digits; room for white space

void wipe_key_text(std::string& text) {
  volatile char* p = text.data();
  for (std::size_t i = 0; i < text.size(); ++i) p[i] = 0;
}

}  // namespace

Result<SecretKey> read_key_file(const std::string& path, std::size_t min_bytes, std::size_t max_bytes) {
  std::string text;
  // Read in place (never longer than this): no copy of the key is left behind in freed memory.
  text.reserve(kMaxKeyFileBytes);
  const std::string error =
      config_detail::read_regular_file(path, text, kMaxKeyFileBytes, config_detail::refuse_unless_private);
  if (!error.empty()) {
    wipe_key_text(text);
    return Error{"cannot use key file " + path + ": " + error};
  }
  Result<SecretKey> key = parse_key_text(text, min_bytes, max_bytes);
  wipe_key_text(text);
  if (!key) return Error{"key file " + path + " holds no key: " + key.error().text};
  return key;
}

Result<std::string> read_private_file(const std::string& path, std::size_t max_bytes) {
  std::string text;
  const std::string error =
      config_detail::read_regular_file(path, text, max_bytes, config_detail::refuse_unless_private);
  if (!error.empty()) {
    wipe_key_text(text);
    return Error{"cannot use " + path + ": " + error};
  }
  return text;
}

}  // namespace cosmic

namespace cosmic::config_detail {

std::string refuse_unless_private(const struct stat& status) {
  if (status.st_uid != ::geteuid() && status.st_uid != 0)
    return "owned by user " + std::to_string(status.st_uid) + ", neither this process's user (" +
           std::to_string(::geteuid()) + ") nor root";
  const Result<void> private_file = check_key_file_mode(status.st_mode);
  return private_file ? std::string() : private_file.error().text;
}

std::optional<LoadedKey> load_key_file(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                       std::vector<std::string>& included, std::size_t min_bytes,
                                       std::size_t max_bytes) {
  const auto file = reader.string(node, path);
  if (!file) return std::nullopt;
  const std::filesystem::path relative(*file);
  const std::string resolved =
      relative.is_absolute()
          ? *file
          : (std::filesystem::path(reader.file()).parent_path() / relative).lexically_normal().string();
  Result<SecretKey> key = read_key_file(resolved, min_bytes, max_bytes);
  if (!key) {
    const std::size_t suggested = std::clamp<std::size_t>(32, min_bytes, max_bytes);
    reader.error_at(node, path, key.error().text,
                    "a file only its owner may read, holding " + std::to_string(min_bytes) + " to " +
                        std::to_string(max_bytes) + " bytes as hexadecimal digits (openssl rand -hex " +
                        std::to_string(suggested) + " > FILE; chmod 600 FILE)");
    return std::nullopt;
  }
  included.push_back(resolved);
  return LoadedKey{resolved, std::move(key).value()};
}

LcmAuthSpec parse_lcm_auth(YamlReader& reader, const YAML::Node& node, const std::string& path,
                           std::vector<std::string>& included) {
  LcmAuthSpec auth;
  if (!reader.check_map(node, path, {"key_file", "accept_key_files", "window", "cost"})) return auth;
  if (has(node, "key_file")) {
    if (auto loaded = load_key_file(reader, node["key_file"], key(path, "key_file"), included, kLcmAuthMinKeyBytes,
                                    kLcmAuthMaxKeyBytes)) {
      auth.key_file = loaded->path;
      auth.key = std::move(loaded->key);
    }
  } else if (!node["key_file"]) {  // present without a value: check_map reports it
    reader.error_at(node, key(path, "key_file"), "missing required key 'key_file'",
                    "a key file: openssl rand -hex 32 > FILE; chmod 600 FILE");
  }
  if (has(node, "accept_key_files") && reader.is_list(node["accept_key_files"], key(path, "accept_key_files"))) {
    const YAML::Node& files = node["accept_key_files"];
    for (std::size_t i = 0; i < files.size(); ++i) {
      auto loaded = load_key_file(reader, files[i], indexed(key(path, "accept_key_files"), i), included,
                                  kLcmAuthMinKeyBytes, kLcmAuthMaxKeyBytes);
      if (!loaded) continue;
      auth.accepted_files.push_back(loaded->path);
      auth.accepted.push_back(std::move(loaded->key));
    }
  }
  if (has(node, "window")) {
    if (auto v = reader.duration(node["window"], key(path, "window"), false)) auth.window = *v;
  }
  if (has(node, "cost")) {
    if (auto v = reader.duration(node["cost"], key(path, "cost"), true)) auth.cost = *v;
  }
  return auth;
}

}  // namespace cosmic::config_detail

// Reading configuration files (the parsing is config_loader.cpp): one read per file, a reload
// that skips an unchanged file, and how an error is printed.
#include "cosmic/config_loader.hpp"
#include "yaml_reader.hpp"

namespace cosmic {

std::string ConfigError::to_string() const {
  std::string out = file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  if (!path.empty()) out += path + ": ";
  out += message;
  if (!valid.empty()) out += " (" + valid + ")";
  return out;
}

namespace {
ConfigResult unreadable(const std::string& path, const std::string& error) {
  ConfigResult result;
  result.errors.push_back(ConfigError{path, 0, 0, "", error, "a readable YAML file"});
  return result;
}
}  // namespace

ConfigResult load_config_file(const std::string& path, const LoadOptions& options) {
  std::string text;
  if (const std::string error = config_detail::read_yaml_file(path, text); !error.empty())
    return unreadable(path, error);
  return parse_config(text, path, options);
}

ConfigResult ConfigFileLoader::load(const std::string& path) {
  last_unchanged_ = false;
  std::string text;
  if (const std::string error = config_detail::read_yaml_file(path, text); !error.empty()) {
    text_.clear();
    return unreadable(path, error);
  }
  if (!text_.empty() && path == path_ && text == text_) {
    last_unchanged_ = true;
    return ConfigResult{config_, {}, {}};
  }
  ConfigResult result = parse_config(text, path);
  if (result.ok() && !text.empty() && result.included_files.empty()) {
    path_ = path;
    text_ = std::move(text);
    config_ = result.config;
  } else {
    text_.clear();
  }
  return result;
}

}  // namespace cosmic

// Helpers that read typed values out of yaml-cpp nodes and record every problem with its
// location. Internal to the config library.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/config_loader.hpp"
#include "cosmic/units.hpp"

namespace cosmic::config_detail {

// Bounds on what one YAML text may cost, so a small hostile file (alias amplification, a
// device, a huge file) cannot stall the control loop or `cosmicctl check`.
inline constexpr std::size_t kMaxYamlBytes = 8u << 20;
// Nodes after every alias is expanded (a 10,000-channel file has about 300,000).
inline constexpr std::uint64_t kMaxYamlNodes = 2'000'000;
// Errors reported per file; the rest are counted in one closing line.
inline constexpr std::size_t kMaxReportedErrors = 100;

// Reads at most kMaxYamlBytes of `path` into `text`; empty string or why not.
std::string read_yaml_file(const std::string& path, std::string& text);

class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  void error(const YAML::Mark& mark, const std::string& path, std::string message, std::string valid = {});
  void error_at(const YAML::Node& node, const std::string& path, std::string message, std::string valid = {});
  // A problem located in another file the configuration names (a DBC file).
  void error_in(ConfigError located);
  std::vector<ConfigError> take_errors();
  // The file whose YAML this reader reads (labels its errors, anchors relative paths in it).
  const std::string& file() const { return file_; }
  // Every error found, also those beyond kMaxReportedErrors.
  std::size_t error_count() const { return errors_.size() + suppressed_; }

  // Parses `text` within the bounds above; nullopt after recording why not. `expected` says
  // what a non-empty document holds.
  std::optional<YAML::Node> load(std::string_view text, const char* expected);

  // True when `node` is a map; reports unknown and duplicate keys against `allowed`.
  bool check_map(const YAML::Node& node, const std::string& path, std::initializer_list<const char*> allowed);
  bool is_list(const YAML::Node& node, const std::string& path);
  // True when map `map` at `path` has key `name` with a value; else reports it missing (a key
  // present without a value is check_map's to report) and returns false.
  bool require(const YAML::Node& map, const std::string& path, const char* name, const char* valid);

  std::optional<std::string> string(const YAML::Node& node, const std::string& path);
  std::optional<bool> boolean(const YAML::Node& node, const std::string& path);
  std::optional<std::uint64_t> unsigned_int(const YAML::Node& node, const std::string& path, std::uint64_t min,
                                            std::uint64_t max);
  // A whole number that may be negative (decimal).
  std::optional<std::int64_t> signed_int(const YAML::Node& node, const std::string& path);
  // A finite decimal number: 12, -0.5, 1e-3.
  std::optional<double> number(const YAML::Node& node, const std::string& path);
  std::optional<Nanos> duration(const YAML::Node& node, const std::string& path, bool allow_zero);
  std::optional<BitRate> bitrate(const YAML::Node& node, const std::string& path);
  std::optional<std::uint64_t> size(const YAML::Node& node, const std::string& path, std::uint64_t max);
  std::optional<double> percent(const YAML::Node& node, const std::string& path);
  std::optional<double> frequency(const YAML::Node& node, const std::string& path);
  // One of `choices`, returned as its index.
  std::optional<std::size_t> choice(const YAML::Node& node, const std::string& path,
                                    std::initializer_list<const char*> choices);
  std::optional<std::vector<std::string>> string_list(const YAML::Node& node, const std::string& path);
  // A name usable as DDS topic and LCM channel: [A-Za-z0-9_.-], 1..64 characters.
  std::optional<std::string> name(const YAML::Node& node, const std::string& path);

 private:
  std::optional<std::string> scalar(const YAML::Node& node, const std::string& path, const char* expected);
  std::string file_;
  std::vector<ConfigError> errors_;
  std::size_t suppressed_ = 0;
};

std::string join(std::initializer_list<const char*> words);

// Key paths as errors name them: "channels[2]", "gateway.metrics" (a top-level key: its name).
inline std::string key(const std::string& path, const std::string& name) {
  return path.empty() ? name : path + "." + name;
}
inline std::string indexed(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}
// Present and not explicitly null.
inline bool has(const YAML::Node& map, const char* name) { return map.IsMap() && map[name] && !map[name].IsNull(); }

}  // namespace cosmic::config_detail

#include "yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <set>

namespace cosmic::config_detail {

std::string join(std::initializer_list<const char*> words) {
  std::string out;
  for (const char* w : words) {
    if (!out.empty()) out += ", ";
    out += w;
  }
  return out;
}

void YamlReader::error(const YAML::Mark& mark, const std::string& path, std::string message, std::string valid) {
  const int line = mark.is_null() ? 0 : mark.line + 1;
  const int column = mark.is_null() ? 0 : mark.column + 1;
  errors_.push_back(ConfigError{file_, line, column, path, std::move(message), std::move(valid)});
}

void YamlReader::error_at(const YAML::Node& node, const std::string& path, std::string message, std::string valid) {
  error(node.Mark(), path, std::move(message), std::move(valid));
}

bool YamlReader::check_map(const YAML::Node& node, const std::string& path, std::initializer_list<const char*> allowed) {
  if (!node.IsMap()) {
    error_at(node, path, "expected a map of keys", "keys: " + join(allowed));
    return false;
  }
  std::set<std::string> seen;
  for (const auto& entry : node) {
    if (!entry.first.IsScalar()) {
      error_at(entry.first, path, "a key must be a plain name", "keys: " + join(allowed));
      continue;
    }
    const std::string key = entry.first.Scalar();
    const std::string key_path = path.empty() ? key : path + "." + key;
    const bool known = std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; });
    if (!known) {
      error_at(entry.first, key_path, "unknown key '" + key + "'", "valid keys here: " + join(allowed));
    } else if (!seen.insert(key).second) {
      error_at(entry.first, key_path, "duplicate key '" + key + "'", "each key once");
    } else if (entry.second.IsNull()) {
      error_at(entry.first, key_path, "value is missing", "a value after '" + key + ":', or remove the key");
    }
  }
  return true;
}

bool YamlReader::is_list(const YAML::Node& node, const std::string& path) {
  if (node.IsSequence()) return true;
  error_at(node, path, "expected a list", "a YAML list, e.g. [a, b] or one '- item' per line");
  return false;
}

std::optional<std::string> YamlReader::scalar(const YAML::Node& node, const std::string& path, const char* expected) {
  if (!node.IsScalar()) {
    error_at(node, path, node.IsNull() ? "value is missing" : "expected a single value, not a list or map", expected);
    return std::nullopt;
  }
  return node.Scalar();
}

std::optional<std::string> YamlReader::string(const YAML::Node& node, const std::string& path) {
  auto value = scalar(node, path, "a text value");
  if (value && value->empty()) {
    error_at(node, path, "must not be empty", "a non-empty text value");
    return std::nullopt;
  }
  return value;
}

std::optional<std::string> YamlReader::name(const YAML::Node& node, const std::string& path) {
  auto value = string(node, path);
  if (!value) return std::nullopt;
  const bool ok = value->size() <= 64 && std::all_of(value->begin(), value->end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                           c == '-' || c == '.';
                  });
  if (!ok) {
    error_at(node, path, "invalid name '" + *value + "'", "1 to 64 characters from A-Z a-z 0-9 _ - .");
    return std::nullopt;
  }
  return value;
}

std::optional<bool> YamlReader::boolean(const YAML::Node& node, const std::string& path) {
  const auto value = scalar(node, path, "true or false");
  if (!value) return std::nullopt;
  if (*value == "true") return true;
  if (*value == "false") return false;
  error_at(node, path, "'" + *value + "' is not a boolean", "true or false");
  return std::nullopt;
}

std::optional<std::uint64_t> YamlReader::unsigned_int(const YAML::Node& node, const std::string& path, std::uint64_t min,
                                                      std::uint64_t max) {
  const std::string range = "a whole number from " + std::to_string(min) + " to " + std::to_string(max);
  const auto value = scalar(node, path, range.c_str());
  if (!value) return std::nullopt;
  std::string_view digits = *value;
  int base = 10;
  if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
    digits.remove_prefix(2);
    base = 16;
  }
  std::uint64_t parsed = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), parsed, base);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size()) {
    error_at(node, path, "'" + *value + "' is not a whole number", range + " (decimal or 0x hex)");
    return std::nullopt;
  }
  if (parsed < min || parsed > max) {
    error_at(node, path, "'" + *value + "' is out of range", range);
    return std::nullopt;
  }
  return parsed;
}

namespace {
template <typename T>
std::optional<T> report(YamlReader& reader, const YAML::Node& node, const std::string& path, const Parsed<T>& parsed,
                        const char* valid) {
  if (parsed.value) return parsed.value;
  // Unit parse errors carry their own "(what would be valid)": do not add a second one.
  const auto open = parsed.error.rfind(" (");
  if (open != std::string::npos && parsed.error.back() == ')') {
    reader.error_at(node, path, parsed.error.substr(0, open), parsed.error.substr(open + 2, parsed.error.size() - open - 3));
    return std::nullopt;
  }
  reader.error_at(node, path, parsed.error, valid);
  return std::nullopt;
}
}  // namespace

std::optional<Nanos> YamlReader::duration(const YAML::Node& node, const std::string& path, bool allow_zero) {
  const auto text = scalar(node, path, "a duration with unit: ns, us, ms, s");
  if (!text) return std::nullopt;
  const auto value = report(*this, node, path, parse_duration(*text), "a duration with unit: ns, us, ms, s");
  if (value && !allow_zero && value->count() == 0) {
    error_at(node, path, "must be greater than zero", "a duration above 0, e.g. 10ms");
    return std::nullopt;
  }
  return value;
}

std::optional<BitRate> YamlReader::bitrate(const YAML::Node& node, const std::string& path) {
  const auto text = scalar(node, path, "a bit rate with unit: bit/s, kbit/s, Mbit/s, Gbit/s");
  if (!text) return std::nullopt;
  return report(*this, node, path, parse_bitrate(*text), "a bit rate with unit: bit/s, kbit/s, Mbit/s, Gbit/s");
}

std::optional<std::uint64_t> YamlReader::size(const YAML::Node& node, const std::string& path, std::uint64_t max) {
  const auto text = scalar(node, path, "a size with unit: B, KiB, MiB");
  if (!text) return std::nullopt;
  const auto value = report(*this, node, path, parse_size(*text), "a size with unit: B, KiB, MiB");
  if (value && *value > max) {
    error_at(node, path, "'" + *text + "' is too large", "at most " + std::to_string(max) + "B");
    return std::nullopt;
  }
  return value;
}

std::optional<double> YamlReader::percent(const YAML::Node& node, const std::string& path) {
  const auto text = scalar(node, path, "a percentage such as 70%");
  if (!text) return std::nullopt;
  return report(*this, node, path, parse_percent(*text), "a percentage from 0% to 100%");
}

std::optional<double> YamlReader::frequency(const YAML::Node& node, const std::string& path) {
  const auto text = scalar(node, path, "a rate with unit: Hz, kHz");
  if (!text) return std::nullopt;
  return report(*this, node, path, parse_frequency(*text), "a rate with unit: Hz, kHz, MHz");
}

std::optional<std::size_t> YamlReader::choice(const YAML::Node& node, const std::string& path,
                                              std::initializer_list<const char*> choices) {
  const auto text = scalar(node, path, ("one of: " + join(choices)).c_str());
  if (!text) return std::nullopt;
  std::size_t index = 0;
  for (const char* c : choices) {
    if (*text == c) return index;
    ++index;
  }
  error_at(node, path, "'" + *text + "' is not allowed here", "one of: " + join(choices));
  return std::nullopt;
}

std::optional<std::vector<std::string>> YamlReader::string_list(const YAML::Node& node, const std::string& path) {
  if (!is_list(node, path)) return std::nullopt;
  std::vector<std::string> out;
  bool ok = true;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const auto item = name(node[i], path + "[" + std::to_string(i) + "]");
    if (item) {
      out.push_back(*item);
    } else {
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return out;
}

}  // namespace cosmic::config_detail

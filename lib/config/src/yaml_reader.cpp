#include "yaml_reader.hpp"

#include "cosmic/transport_limits.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace cosmic::config_detail {

std::string join(std::initializer_list<const char*> words) {
  std::string out;
  for (const char* w : words) {
    if (!out.empty()) out += ", ";
    out += w;
  }
  return out;
}

std::string read_yaml_file(const std::string& path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "cannot read the file";
  text.resize(kMaxYamlBytes + 1);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxYamlBytes) return "the file is larger than " + std::to_string(kMaxYamlBytes >> 20) + " MiB";
  if (in.bad()) return "cannot read the file";
  return {};
}

namespace {

// Counts the nodes of a YAML stream as if every alias were expanded, without building it:
// each anchored node's expanded size is remembered and an alias adds it. Stops counting at the
// limit and keeps where the limit was crossed.
class ExpansionCounter final : public YAML::EventHandler {
 public:
  explicit ExpansionCounter(std::uint64_t limit) : limit_(limit) {}
  bool exceeded() const { return exceeded_; }
  const YAML::Mark& where() const { return where_; }
  bool by_alias() const { return by_alias_; }

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    const auto size = sizes_.find(anchor);
    add(size == sizes_.end() ? 1 : size->second, mark, true);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Frame {
    std::uint64_t size = 1;
    YAML::anchor_t anchor = 0;
  };
  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    if (anchor) sizes_[anchor] = 1;
    add(1, mark, false);
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    count(1, mark, false);  // the collection itself; its children arrive as events
    stack_.push_back({1, anchor});
  }
  void close() {
    const Frame done = stack_.back();
    stack_.pop_back();
    if (done.anchor) sizes_[done.anchor] = done.size;
    if (!stack_.empty()) stack_.back().size = saturated(stack_.back().size + done.size);
  }
  // A leaf (1) or an alias (the size of what it repeats) inside the innermost collection.
  void add(std::uint64_t nodes, const YAML::Mark& mark, bool alias) {
    if (!stack_.empty()) stack_.back().size = saturated(stack_.back().size + nodes);
    count(nodes, mark, alias);
  }
  void count(std::uint64_t nodes, const YAML::Mark& mark, bool alias) {
    total_ = saturated(total_ + nodes);
    if (total_ > limit_ && !exceeded_) {
      exceeded_ = true;
      where_ = mark;
      by_alias_ = alias;
    }
  }
  std::uint64_t saturated(std::uint64_t value) const { return std::min(value, limit_ + 1); }

  std::uint64_t limit_;
  std::uint64_t total_ = 0;
  std::vector<Frame> stack_;
  std::map<YAML::anchor_t, std::uint64_t> sizes_;
  bool exceeded_ = false;
  bool by_alias_ = false;
  YAML::Mark where_ = YAML::Mark::null_mark();
};

// Cheap first: a text without '*' has no alias, and a small one cannot hold many nodes.
bool worth_counting(std::string_view text) {
  return text.find('*') != std::string_view::npos || text.size() > (1u << 20);
}

}  // namespace

std::optional<YAML::Node> YamlReader::load(std::string_view text, const char* expected) {
  if (text.size() > kMaxYamlBytes) {
    error(YAML::Mark(), "", "the document is larger than " + std::to_string(kMaxYamlBytes >> 20) + " MiB",
          "a smaller file (split it)");
    return std::nullopt;
  }
  try {
    if (worth_counting(text)) {
      std::istringstream stream{std::string(text)};
      YAML::Parser parser(stream);
      ExpansionCounter counter(kMaxYamlNodes);
      // The first document only: it is the one YAML::Load reads below. (yaml-cpp's event parser
      // also yields an endless run of empty documents after some malformed input, e.g. a
      // leading ',': counting on would stop only at the node limit, with a misleading error, after
      // 2,000,000 calls; found by fuzz_control.)
      parser.HandleNextDocument(counter);
      if (counter.exceeded()) {
        error(counter.where(), "",
              counter.by_alias() ? "aliases expand the document beyond " + std::to_string(kMaxYamlNodes) + " nodes"
                                 : "the document has more than " + std::to_string(kMaxYamlNodes) + " nodes",
              "fewer nodes; an alias (*name) counts every node it repeats");
        return std::nullopt;
      }
    }
    YAML::Node root = YAML::Load(std::string(text));
    if (!root || root.IsNull()) {
      error(YAML::Mark(), "", "the document is empty", expected);
      return std::nullopt;
    }
    return root;
  } catch (const YAML::ParserException& e) {
    error(e.mark, "", "YAML syntax error: " + e.msg, "well-formed YAML");
    return std::nullopt;
  }
}

std::vector<ConfigError> YamlReader::take_errors() {
  if (suppressed_ > 0) {
    errors_.push_back(ConfigError{file_, 0, 0, "", std::to_string(suppressed_) + " more error(s) not shown",
                                  "fix the errors above and check again"});
    suppressed_ = 0;
  }
  return std::move(errors_);
}

void YamlReader::error(const YAML::Mark& mark, const std::string& path, std::string message, std::string valid) {
  if (errors_.size() >= kMaxReportedErrors) {
    ++suppressed_;
    return;
  }
  const int line = mark.is_null() ? 0 : mark.line + 1;
  const int column = mark.is_null() ? 0 : mark.column + 1;
  errors_.push_back(ConfigError{file_, line, column, path, std::move(message), std::move(valid)});
}

void YamlReader::error_in(ConfigError located) {
  if (errors_.size() >= kMaxReportedErrors) {
    ++suppressed_;
    return;
  }
  errors_.push_back(std::move(located));
}

void YamlReader::error_at(const YAML::Node& node, const std::string& path, std::string message, std::string valid) {
  error(node.Mark(), path, std::move(message), std::move(valid));
}

bool YamlReader::check_map(const YAML::Node& node, const std::string& path,
                           std::initializer_list<const char*> allowed) {
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

bool YamlReader::require(const YAML::Node& map, const std::string& path, const char* name, const char* valid) {
  if (has(map, name)) return true;
  if (map.IsMap() && map[name]) return false;
  error_at(map, path.empty() ? name : key(path, name), std::string("missing required key '") + name + "'", valid);
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
  const bool ok = value->size() <= kMaxNameLength && std::all_of(value->begin(), value->end(), [](char c) {
                    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                           c == '-' || c == '.';
                  });
  if (!ok) {
    error_at(node, path, "invalid name " + quote_value(*value),
             "1 to " + std::to_string(kMaxNameLength) + " characters from A-Z a-z 0-9 _ - .");
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

std::optional<std::uint64_t> YamlReader::unsigned_int(const YAML::Node& node, const std::string& path,
                                                      std::uint64_t min, std::uint64_t max) {
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
  const bool all_digits = !digits.empty() && end == digits.data() + digits.size();
  if (ec == std::errc::result_out_of_range && all_digits) {  // 2^64 and above, 5,000 digits
    error_at(node, path, quote_value(*value) + " is out of range (above 2^64 - 1)", range);
    return std::nullopt;
  }
  if (ec != std::errc() || !all_digits) {
    error_at(node, path, quote_value(*value) + " is not a whole number", range + " (decimal or 0x hex)");
    return std::nullopt;
  }
  if (parsed < min || parsed > max) {
    error_at(node, path, quote_value(*value) + " is out of range", range);
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
    reader.error_at(node, path, parsed.error.substr(0, open),
                    parsed.error.substr(open + 2, parsed.error.size() - open - 3));
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

std::optional<std::int64_t> YamlReader::signed_int(const YAML::Node& node, const std::string& path) {
  const char* expected = "a whole number, e.g. -3 or 42";
  const auto value = scalar(node, path, expected);
  if (!value) return std::nullopt;
  std::int64_t parsed = 0;
  const auto [end, ec] = std::from_chars(value->data(), value->data() + value->size(), parsed);
  if (ec != std::errc() || end != value->data() + value->size()) {
    error_at(
        node, path,
        quote_value(*value) + (ec == std::errc::result_out_of_range ? " is out of range" : " is not a whole number"),
        expected);
    return std::nullopt;
  }
  return parsed;
}

std::optional<double> YamlReader::number(const YAML::Node& node, const std::string& path) {
  const char* expected = "a decimal number, e.g. 0, -0.5 or 1e3";
  const auto value = scalar(node, path, expected);
  if (!value) return std::nullopt;
  double parsed = 0;
  const auto [end, ec] = std::from_chars(value->data(), value->data() + value->size(), parsed);
  if (ec != std::errc() || end != value->data() + value->size() || !std::isfinite(parsed)) {
    error_at(node, path, quote_value(*value) + " is not a finite decimal number", expected);
    return std::nullopt;
  }
  return parsed;
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

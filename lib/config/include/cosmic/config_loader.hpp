// YAML configuration: schema, units and strict validation. Every problem of a document is
// collected (never the first only) with its file:line:column and key path.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cosmic/model.hpp"

namespace cosmic {

struct ConfigError {
  std::string file;
  int line = 0;         // 1-based
  int column = 0;       // 1-based
  std::string path;     // key path, e.g. channels[2].period
  std::string message;  // what is wrong
  std::string valid;    // what would be valid (may be empty)
  // "FILE:LINE:COL: key.path: what is wrong (what would be valid)"
  std::string to_string() const;
};

struct ConfigResult {
  Config config;  // meaningful only when errors is empty
  std::vector<ConfigError> errors;
  std::vector<std::string> included_files;  // other files the document names and that were read (DBC)
  bool ok() const { return errors.empty(); }
};

struct ChannelsResult {
  std::vector<ChannelSpec> channels;
  std::vector<ConfigError> errors;
  bool ok() const { return errors.empty(); }
};

// What a load leaves out of its checks.
struct LoadOptions {
  // The DDS Security documents (a secure segment's `governance` and `permissions`) are about to be
  // written (`cosmicctl security permissions`): their paths are resolved but the files are neither
  // required to exist nor read nor checked. Everything else, the other four files included, is.
  bool security_documents_pending = false;
};

// Parses a whole gateway configuration. `file_name` labels the errors and anchors the relative
// paths the document names (a CAN segment's background dbc: FILE), which are read.
ConfigResult parse_config(std::string_view text, const std::string& file_name, const LoadOptions& options = {});
// Reads and parses a file; an unreadable file is one error at 0:0.
ConfigResult load_config_file(const std::string& path, const LoadOptions& options = {});

// load_config_file() for a file that is read again and again (cosmicd's reloads): a file whose
// bytes are those of the last valid document it loaded from that path is not parsed again, its
// Config is returned from memory (parsing is most of the cost of reloading a large, unchanged
// file). Any change of the bytes, the path or a failed load parses afresh, and so does every load
// of a document that names other files (DBC), which may have changed. One caller at a time.
class ConfigFileLoader {
 public:
  ConfigResult load(const std::string& path);
  // Whether the last load() returned the remembered Config without parsing.
  bool last_was_unchanged() const { return last_unchanged_; }

 private:
  std::string path_;
  std::string text_;  // of the remembered document; empty: nothing remembered
  Config config_;
  bool last_unchanged_ = false;
};

struct SegmentResult {
  SegmentSpec segment;  // meaningful only when errors is empty
  std::vector<ConfigError> errors;
  bool ok() const { return errors.empty(); }
};

// Parses one segment map for a segment added at run time (`cosmicctl replay`), checked as a
// configuration's segment is (a replay's recording read and scanned); its name must not be one of
// `running`'s segments. Key paths start at "segment".
SegmentResult parse_segment(std::string_view text, const std::string& file_name, const Config& running);

// Parses channel definitions for a runtime bind: a document with a `channels:` list, a list of
// channel maps, or one channel map, validated against the segments of `running`. A channel one of
// `running`'s FMUs publishes names it in ChannelSpec::fmu_publishers, as at load.
ChannelsResult parse_channels(std::string_view text, const std::string& file_name, const Config& running);

}  // namespace cosmic

namespace cosmic {

// One channel as a YAML flow map that parse_channels() reads back to an equal ChannelSpec
// (durations in ns, sizes in B, subject in hex).
std::string channel_to_yaml(const ChannelSpec& channel);

}  // namespace cosmic

// Every file in tests/unit/bad_configs/ is a broken configuration; each must be answered with
// the exact FILE:LINE:COL, key path and message, and nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "cosmic/build_paths.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

struct Expected {
  int line;
  int column;
  std::string path;
  std::string fragment;  // part of the message or of what would be valid
};

struct BadConfig {
  std::string file;
  std::vector<Expected> errors;  // every error of the file, in order
};

std::string bad_config_path(const std::string& name) {
  return std::string(cosmic::build_paths::bad_config_dir) + "/" + name;
}

std::string describe_errors(const std::vector<ConfigError>& errors) {
  std::string out;
  for (const auto& e : errors) out += "  " + e.to_string() + "\n";
  return out;
}

// clang-format off
const std::vector<BadConfig> kBadConfigs = {
  // unknown keys
  {"unknown_top_key.yaml", {{3, 1, "gatway", "unknown key 'gatway'"}}},
  {"unknown_segment_key.yaml", {{6, 5, "segments[0].bitrates", "unknown key 'bitrates'"}}},
  {"key_of_other_segment_type.yaml", {{6, 5, "segments[0].url", "unknown key 'url' (valid keys here: name, type, interface"}}},
  {"unknown_channel_key.yaml", {{10, 5, "channels[0].priority", "unknown key 'priority'"}}},
  // wrong types
  {"list_for_scalar.yaml", {{5, 14, "segments[0].bitrate", "expected a single value, not a list or map"}}},
  {"segments_not_list.yaml", {{2, 3, "segments", "expected a list"},
                              // without a segments list every segment name is unknown
                              {8, 18, "channels[0].publishers[0]", "unknown segment 'lan' (one of the segments: (none defined))"},
                              {9, 19, "channels[0].subscribers[0]", "unknown segment 'lan'"}}},
  {"channel_not_map.yaml", {{7, 5, "channels[0]", "expected a map of keys"}}},
  {"bool_not_boolean.yaml", {{6, 9, "segments[0].fd", "'yes' is not a boolean (true or false)"}}},
  {"root_is_list.yaml", {{1, 1, "", "expected a map of keys (keys: gateway, segments, channels, components, fmus, recording)"}}},
  {"subject_not_a_number.yaml", {{8, 14, "channels[0].subject", "'distance' is not a whole number"}}},
  {"value_missing.yaml", {{11, 5, "channels[0].reaction_time", "value is missing"},
                          {12, 5, "channels[0].temp_validity", "value is missing"}}},
  // out-of-range values
  {"node_id_out_of_range.yaml", {{2, 16, "gateway.can_node_id", "'200' is out of range (a whole number from 0 to 127)"}}},
  {"can_bitrate_too_high.yaml", {{5, 14, "segments[0].bitrate", "CAN nominal bit rate above 1Mbit/s"}}},
  {"percent_out_of_range.yaml", {{6, 22, "segments[0].max_utilization", "'120%' is out of range (0% to 100%)"}}},
  {"zero_period.yaml", {{10, 13, "channels[0].period", "must be greater than zero"}}},
  {"zero_max_rate.yaml", {{10, 15, "channels[0].max_rate", "'0Hz' is out of range"}}},
  {"subject_zero.yaml", {{8, 14, "channels[0].subject", "'0' is out of range"}}},
  {"reserved_etag.yaml", {{12, 11, "channels[0].etag", "'3' is out of range (a whole number from 101 to 16383)"}}},
  {"payload_too_large.yaml", {{10, 14, "channels[0].payload", "'2MiB' is too large (at most 1048576B)"}}},
  {"data_bitrate_below_nominal.yaml", {{7, 19, "segments[0].data_bitrate", "data bit rate out of range"}}},
  {"max_message_size_too_small.yaml", {{4, 23, "segments[0].max_message_size", "too small (more than 96B)"}}},
  {"interface_too_long.yaml", {{4, 16, "segments[0].interface", "interface name 'can-interface-name0' is too long (at most 15 characters)"}}},
  {"bad_class.yaml", {{9, 12, "channels[0].class", "'firm' is not allowed here (one of: hrt, srt, nrt)"}}},
  {"unknown_segment_type.yaml", {{3, 11, "segments[0].type", "'zenoh' is not allowed here (one of: can, dds, lcm, replay)"}}},
  {"bad_own_datagrams.yaml", {{6, 20, "segments[1].own_datagrams", "'discard' is not allowed here (one of: cut, drop)"}}},
  {"bad_reliability.yaml", {{4, 18, "segments[0].reliability", "'sometimes' is not allowed here (one of: reliable, best_effort)"}}},
  {"invalid_name.yaml", {{7, 11, "channels[0].name", "invalid name 'my channel'"}}},
  {"bad_lcm_url.yaml", {{6, 10, "segments[1].url", "unsupported LCM URL 'http://239.255.76.67:7667'"}}},
  {"bad_discovery_server.yaml", {{4, 23, "segments[0].discovery_server", "'127.0.0.1' is not IP:PORT"}}},
  {"relative_control_socket.yaml", {{2, 19, "gateway.control_socket", "'run/cosmicd.sock' is not an absolute path"}}},
  // quantities past what their type holds: a located, precise message (never an overflow)
  {"tiny_max_rate.yaml", {{10, 15, "channels[0].max_rate", "'0.00000000001Hz' is out of range (from 0.000000001Hz"}}},
  {"subject_above_64_bits.yaml", {{8, 14, "channels[0].subject", "'18446744073709551616' is out of range (above 2^64 - 1)"}}},
  {"subject_5000_digits.yaml", {{8, 14, "channels[0].subject", "'111111111111111111111111...' (5000 characters) is out of range (above 2^64 - 1)"}}},
  {"period_5000_digits.yaml", {{10, 13, "channels[0].period", "(5002 characters) has 5000 digits (at most 30,"}}},
  // transport limits (cosmic/transport_limits.hpp), the same the adapters apply
  {"lcm_name_too_long.yaml", {{7, 11, "channels[0].name", "segment 'viz' cannot carry this channel: LCM channel names have at most 63 characters"}}},
  // bad units
  {"bad_duration_unit.yaml", {{10, 13, "channels[0].period", "unknown unit 'msec' in '10 msec' (a duration such as 250us, 10ms, 1.5s)"}}},
  {"missing_unit.yaml", {{11, 20, "channels[0].reaction_time", "'5' has no unit"}}},
  {"negative_duration.yaml", {{4, 20, "segments[0].latency_bound", "'-2ms' is not a number with a unit"}}},
  {"fractional_payload.yaml", {{10, 14, "channels[0].payload", "'1.5B' is not a whole number of bytes"}}},
  // names: dangling and duplicate
  {"dangling_segment.yaml", {{11, 19, "channels[0].subscribers[0]", "unknown segment 'vis' (one of the segments: lan, viz)"}}},
  {"duplicate_segment_name.yaml", {{6, 11, "segments[2].name", "duplicate segment name 'lan' (a name not used by another segment (first at line 2))"}}},
  // overlapping segments: one network attached twice would loop every message
  {"overlapping_lcm_port.yaml", {{7, 10, "segments[1].url", "segment 'viz2' attaches the same network as segment 'viz' (line 2): UDP port 7667"}}},
  {"overlapping_lcm_default_url.yaml", {{5, 5, "segments[1].url", "as segment 'viz' (line 2): UDP port 7667"}}},
  {"overlapping_dds_domain.yaml", {{7, 13, "segments[1].domain", "as segment 'lan' (line 2): DDS domain 3"}}},
  {"overlapping_can_interface.yaml", {{4, 41, "segments[2].interface", "as segment 'body' (line 2): CAN interface can0"},
                                      {5, 41, "segments[3].interface", "as segment 'body' (line 2): CAN interface can0"}}},
  {"duplicate_channel_name.yaml", {{12, 11, "channels[1].name", "duplicate channel name 'c1'"}}},
  {"duplicate_subject.yaml", {{13, 14, "channels[1].subject", "subject already used by channel 'c1'"}}},  // 0x10 == 16
  {"duplicate_etag.yaml", {{18, 11, "channels[1].etag", "etag already used by channel 'c1'"}}},
  {"duplicate_subscriber.yaml", {{11, 24, "channels[0].subscribers[1]", "segment 'viz' listed twice"}}},
  {"duplicate_key.yaml", {{11, 5, "channels[0].payload", "duplicate key 'payload'"}}},
  // bindings
  {"no_publishers.yaml", {{7, 5, "channels[0].publishers", "missing required key 'publishers'"}}},
  {"empty_subscribers.yaml", {{11, 18, "channels[0].subscribers", "no segment listed"}}},
  {"both_publisher_and_subscriber.yaml", {{11, 24, "channels[0].subscribers[1]", "segment 'lan' is both publisher and subscriber of this channel"}}},
  // channel and segment rules
  {"period_and_max_rate.yaml", {{11, 15, "channels[0].max_rate", "period and max_rate both given"}}},
  {"hrt_without_reaction_time.yaml", {{9, 5, "channels[0].reaction_time", "an hrt or srt channel needs reaction_time"}}},
  {"data_bitrate_without_fd.yaml", {{6, 19, "segments[0].data_bitrate", "data_bitrate needs fd: true"}}},
  {"errors_without_window.yaml", {{6, 13, "segments[0].errors.window", "missing required key 'window'"}}},
  {"missing_segment_type.yaml", {{2, 5, "segments[0].type", "missing required key 'type' (type: can, dds, lcm or replay)"}}},
  // documents
  {"yaml_syntax_error.yaml", {{7, 10, "", "YAML syntax error: end of sequence flow not found"}}},
  {"empty.yaml", {{1, 1, "", "the document is empty"}}},
  {"alias_bomb.yaml", {{7, 8, "", "aliases expand the document beyond 2000000 nodes"}}},
  {"missing_segments.yaml", {{1, 1, "segments", "missing required key 'segments'"},
                             {7, 18, "channels[0].publishers[0]", "unknown segment 'lan'"},
                             {8, 19, "channels[0].subscribers[0]", "unknown segment 'viz'"}}},
  // several errors in one file, all reported in one run, in document order
  {"several_errors.yaml", {{2, 16, "gateway.can_node_id", "'300' is out of range"},
                           {7, 14, "segments[0].bitrate", "'fast' is not a number with a unit"},
                           {10, 5, "segments[1].colour", "unknown key 'colour'"},
                           {12, 5, "channels[0].reaction_time", "an hrt or srt channel needs reaction_time"},
                           // an invalid segment is still known by its name: no "unknown segment 'lan'"
                           {17, 19, "channels[0].subscribers[0]", "unknown segment 'nowhere' (one of the segments: bus, lan)"},
                           {21, 14, "channels[1].payload", "'8' has no unit"},
                           {23, 19, "channels[1].subscribers[0]", "segment 'lan' is both publisher and subscriber"}}},
};
// clang-format on

class BadConfigTest : public ::testing::TestWithParam<BadConfig> {};

TEST_P(BadConfigTest, ReportsEveryErrorWithLocation) {
  const BadConfig& bad = GetParam();
  const std::string path = bad_config_path(bad.file);
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  const ConfigResult result = load_config_file(path);
  EXPECT_FALSE(result.ok());
  ASSERT_EQ(result.errors.size(), bad.errors.size()) << describe_errors(result.errors);
  for (std::size_t i = 0; i < bad.errors.size(); ++i) {
    const Expected& want = bad.errors[i];
    const ConfigError& got = result.errors[i];
    EXPECT_EQ(got.file, path);
    EXPECT_EQ(got.line, want.line) << got.to_string();
    EXPECT_EQ(got.column, want.column) << got.to_string();
    EXPECT_EQ(got.path, want.path) << got.to_string();
    EXPECT_NE(got.to_string().find(want.fragment), std::string::npos) << got.to_string();
    EXPECT_FALSE(got.message.empty());
    // FILE:LINE:COL: key.path: what is wrong (what would be valid)
    const std::string prefix = path + ":" + std::to_string(want.line) + ":" + std::to_string(want.column) + ": " +
                               (want.path.empty() ? "" : want.path + ": ");
    EXPECT_EQ(got.to_string().rfind(prefix, 0), 0u) << got.to_string();
    if (!got.valid.empty()) {
      EXPECT_EQ(got.to_string(), prefix + got.message + " (" + got.valid + ")");
      // One "(what would be valid)", not two.
      EXPECT_EQ(got.message.find(got.valid), std::string::npos) << got.to_string();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Files, BadConfigTest, ::testing::ValuesIn(kBadConfigs), [](const auto& info) {
  std::string name = info.param.file.substr(0, info.param.file.find('.'));
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
});

TEST(BadConfigs, AtLeast25DistinctFilesAllCovered) {
  std::set<std::string> on_disk;
  for (const auto& entry : std::filesystem::directory_iterator(cosmic::build_paths::bad_config_dir)) {
    if (entry.path().extension() == ".yaml") on_disk.insert(entry.path().filename().string());
  }
  std::set<std::string> in_table;
  for (const auto& bad : kBadConfigs) EXPECT_TRUE(in_table.insert(bad.file).second) << "listed twice: " << bad.file;
  EXPECT_EQ(on_disk, in_table);  // every file is checked, every checked file exists
  EXPECT_GE(in_table.size(), 25u);
}

TEST(BadConfigs, UnreadableFile) {
  const std::string path = bad_config_path("no_such_file.yaml");
  const ConfigResult result = load_config_file(path);
  ASSERT_EQ(result.errors.size(), 1u);
  EXPECT_EQ(result.errors[0].line, 0);
  EXPECT_EQ(result.errors[0].column, 0);
  EXPECT_EQ(result.errors[0].to_string(), path + ":0:0: cannot read the file (a readable YAML file)");
}

TEST(BadConfigs, FileNameOnlyLabelsErrors) {
  const ConfigResult result = parse_config("segments: []\nchannels: []\nextra: 1\n", "label.yaml");
  ASSERT_EQ(result.errors.size(), 1u) << describe_errors(result.errors);
  EXPECT_EQ(result.errors[0].to_string(),
            "label.yaml:3:1: extra: unknown key 'extra' (valid keys here: gateway, segments, channels, components, "
            "fmus, recording)");
}

TEST(BadConfigs, ArbitraryBytesNeverCrash) {
  // A few hostile inputs: each yields errors (or a valid empty config), never an exception.
  for (const char* text : {"\t\t:", "{{{{", "- - - -", "segments: &a [*a]", "channels: !!binary AAAA", "\"unterminated",
                           "segments:\n  - name: x\n    type: can\n    interface: [\n", "? complex key\n: value\n"}) {
    EXPECT_NO_THROW({
      const ConfigResult r = parse_config(text, "fuzz.yaml");
      EXPECT_FALSE(r.ok()) << text;
    }) << text;
  }
}

}  // namespace
}  // namespace cosmic

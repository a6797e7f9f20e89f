// The `recording:` section (docs/yaml-reference.md, docs/recording.md): defaults, what is read,
// a relative directory anchored at the file, channel selection by name and glob, and every
// mistake with its location and key path.
#include <gtest/gtest.h>

#include "config_test_support.hpp"
#include "cosmic/config_loader.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

std::string recording_document(const std::string& recording) {
  return "segments:\n"
         "  - {name: lan, type: dds, domain: 3}\n"
         "  - {name: body, type: can, interface: can0, bitrate: 500kbit/s}\n"
         "channels:\n"
         "  - {name: drive_cmd, subject: 0x10, class: nrt, publishers: [lan], subscribers: [body]}\n"
         "  - {name: drive_state, subject: 0x11, class: nrt, publishers: [body], subscribers: [lan]}\n"
         "  - {name: obstacle, subject: 0x12, class: nrt, publishers: [body], subscribers: [lan]}\n" +
         recording;
}

TEST(RecordingConfig, WithoutTheSectionNothingIsRecorded) {
  const ConfigResult r = parse_config(recording_document(""), "/etc/cosmic/g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  EXPECT_FALSE(r.config.recording.enabled());
}

TEST(RecordingConfig, DefaultsSelectEveryChannelWithZstdChunksAndRotation) {
  const ConfigResult r = parse_config(recording_document("recording: {directory: rec}\n"), "/etc/cosmic/g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  const RecordingSpec& rec = r.config.recording;
  EXPECT_TRUE(rec.enabled());
  EXPECT_EQ(rec.directory, "/etc/cosmic/rec");
  EXPECT_EQ(rec.compression, RecordCompression::zstd);
  EXPECT_EQ(rec.typed_encoding, TypedEncoding::cdr);
  EXPECT_EQ(rec.chunk_size, 1u << 20);
  EXPECT_EQ(rec.rotate_size, 256u << 20);
  EXPECT_EQ(rec.rotate_duration, Nanos(10min));
  EXPECT_EQ(rec.memory, 16u << 20);
  EXPECT_TRUE(rec.start);
  EXPECT_TRUE(rec.candump.empty());
  EXPECT_TRUE(rec.selects("drive_cmd"));
  EXPECT_TRUE(rec.selects("obstacle"));
}

TEST(RecordingConfig, ReadsEveryKeyAndSelectsByNameAndGlob) {
  const ConfigResult r = parse_config(recording_document("recording:\n"
                                                         "  directory: /var/lib/cosmicd/rec/\n"
                                                         "  channels: [obstacle, 'drive_c*']\n"
                                                         "  compression: none\n"
                                                         "  typed_encoding: json\n"
                                                         "  chunk_size: 64KiB\n"
                                                         "  rotate: {size: 8MiB, duration: 30s}\n"
                                                         "  memory: 4MiB\n"
                                                         "  start: false\n"
                                                         "  candump: [body]\n"),
                                      "g.yaml");
  ASSERT_TRUE(r.ok()) << test::errors_text(r);
  const RecordingSpec& rec = r.config.recording;
  EXPECT_EQ(rec.directory, "/var/lib/cosmicd/rec/");
  EXPECT_EQ(rec.compression, RecordCompression::none);
  EXPECT_EQ(rec.typed_encoding, TypedEncoding::json);
  EXPECT_EQ(rec.chunk_size, 64u << 10);
  EXPECT_EQ(rec.rotate_size, 8u << 20);
  EXPECT_EQ(rec.rotate_duration, Nanos(30s));
  EXPECT_EQ(rec.memory, 4u << 20);
  EXPECT_FALSE(rec.start);
  EXPECT_EQ(rec.candump, std::vector<std::string>{"body"});
  EXPECT_TRUE(rec.selects("obstacle"));
  EXPECT_TRUE(rec.selects("drive_cmd"));
  EXPECT_FALSE(rec.selects("drive_state"));
  EXPECT_FALSE(rec.selects("obstacles"));
}

TEST(RecordingConfig, EveryMistakeIsReportedWithItsPlace) {
  struct Case {
    std::string recording;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"recording: {channels: [obstacle]}\n", "g.yaml:8:12: recording.directory: missing required key 'directory'"},
      {"recording: {directory: rec, channels: [obstacel]}\n",
       "g.yaml:8:40: recording.channels[0]: unknown channel 'obstacel' (a channel of this file, or a glob such as "
       "'drive*')"},
      {"recording: {directory: rec, channels: obstacle}\n", "recording.channels"},
      {"recording: {directory: rec, compression: lz5}\n", "recording.compression"},
      {"recording: {directory: rec, typed_encoding: protobuf}\n", "g.yaml:8:45: recording.typed_encoding"},
      {"recording: {directory: rec, chunk_size: 1KiB}\n",
       "recording.chunk_size: chunk_size below 4KiB (from 4KiB to 64MiB, e.g. 1MiB)"},
      {"recording: {directory: rec, chunk_size: 1GiB}\n", "recording.chunk_size"},
      {"recording: {directory: rec, memory: 100KiB}\n", "recording.memory: memory below 1MiB"},
      {"recording: {directory: rec, rotate: {size: 100KiB}}\n", "recording.rotate.size: rotation size below 1MiB"},
      {"recording: {directory: rec, chunk_size: 8MiB, rotate: {size: 2MiB}}\n",
       "recording.rotate.size: rotation size below chunk_size"},
      {"recording: {directory: rec, rotate: {duration: 10ms}}\n",
       "recording.rotate.duration: rotation duration out of range (from 1s to 24h"},
      {"recording: {directory: rec, rotate: {files: 3}}\n", "recording.rotate.files"},
      {"recording: {directory: rec, start: maybe}\n", "recording.start"},
      {"recording: {directory: rec, candump: [lan]}\n",
       "recording.candump[0]: segment 'lan' is not a CAN segment (a CAN segment of this file)"},
      {"recording: {directory: rec, candump: [bus]}\n", "recording.candump[0]: unknown segment 'bus'"},
      {"recording: {directory: rec, format: mcap}\n", "recording.format"},
      {"recording: [rec]\n", "recording"},
  };
  for (const Case& c : cases) {
    const ConfigResult r = parse_config(recording_document(c.recording), "g.yaml");
    test::expect_refused_with(r, c.expected);
  }
}

TEST(RecordingConfig, AllMistakesOfTheSectionAreReportedAtOnce) {
  const ConfigResult r = parse_config(
      recording_document("recording: {directory: rec, channels: [nope], memory: 1KiB, candump: [lan]}\n"), "g.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.errors.size(), 3u) << test::errors_text(r);
}

}  // namespace
}  // namespace cosmic

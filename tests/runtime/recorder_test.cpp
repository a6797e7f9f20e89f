// The recorder (cosmic/recorder.hpp) over real files in a temporary directory, read back with the
// MCAP reader: events offered while recording come out of the file with their channel, source
// segment, origin, sequence, arrival and creation times and contents (a typed channel's as JSON,
// with its schema); files rotate by size, each whole; nothing is recorded before start() or after
// stop(), and everything queued before stop(); a directory that cannot be written refuses start()
// with the reason; an event too long for the queue, or of a channel the recorder does not know, is
// counted, not written, and so is every event of a chunk whose write failed.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/mcap_writer.hpp"
#include "cosmic/recorder.hpp"
#include "cosmic/recording_info.hpp"
#include "recording_file.hpp"

namespace cosmic {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class CollectingLogger final : public Logger {
 public:
  void log(LogLevel, std::string_view message) override {
    const std::lock_guard lock(mutex_);
    lines_.emplace_back(message);
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

Nanos steady_now() { return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()); }

std::int64_t utc_now() {
  return std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count();
}

ChannelType distance_type() {
  FieldType f32;
  f32.kind = FieldType::Kind::scalar;
  f32.scalar = ScalarKind::float32;
  ChannelType type;
  type.fields.push_back(TypeField{"distance", f32, "m", std::nullopt, std::nullopt, std::nullopt});
  return type;
}

std::vector<std::uint8_t> float_bytes(float value) {
  std::vector<std::uint8_t> out(4);
  std::memcpy(out.data(), &value, 4);
  return out;
}

class RecorderTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("recorder_test_" + std::to_string(::getpid()) + "_" +
                                           testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    spec_.directory = (dir_ / "rec").string();
    spec_.chunk_size = 4096;
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<RecordedChannel> channels() const {
    RecordedChannel bytes;
    bytes.id = 1;
    bytes.name = "obstacle";
    bytes.metadata = {{"subject", "0x10"}, {"class", "hrt"}};
    RecordedChannel typed;
    typed.id = 2;
    typed.name = "range";
    typed.json = std::make_shared<const JsonRepresentation>(distance_type());
    typed.json_schema = R"({"type":"object"})";
    return {bytes, typed};
  }

  std::vector<fs::path> files() const {
    std::vector<fs::path> out;
    for (const auto& entry : fs::directory_iterator(spec_.directory)) out.push_back(entry.path());
    std::sort(out.begin(), out.end());
    return out;
  }

  static McapFile read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto file = read_mcap(bytes);
    EXPECT_TRUE(file) << path << ": " << (file ? "" : file.error().text);
    return file ? std::move(file).value() : McapFile{};
  }

  static EventHeader header(std::uint64_t origin, std::uint32_t sequence, std::int64_t created) {
    EventHeader h;
    h.origin = origin;
    h.sequence = sequence;
    h.created_ns = created;
    return h;
  }

  fs::path dir_;
  RecordingSpec spec_;
  CollectingLogger log_;
};

TEST_F(RecorderTest, EventsComeBackWithTheirChannelSegmentOriginTimesAndContents) {
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  recorder.set_segment_names({"body-can", "lan"});
  const std::vector<std::uint8_t> before{0xEE};
  recorder.offer(1, 0, header(0xA1, 1, 5), steady_now(), before);  // not recording yet
  ASSERT_TRUE(recorder.start().ok());
  const std::int64_t started = utc_now();
  const std::vector<std::uint8_t> obstacle{1, 2, 3};
  recorder.offer(1, 0, header(0xA1, 7, 1'000), steady_now(), obstacle);
  recorder.offer(1, 1, header(0xB2, 8, 2'000), steady_now(), obstacle);
  recorder.offer(2, 1, header(0xA1, 9, 3'000), steady_now(), float_bytes(1.5f));
  recorder.stop();
  recorder.offer(1, 0, header(0xA1, 10, 4'000), steady_now(), before);  // stopped
  const RecorderStatus status = recorder.status();
  EXPECT_FALSE(status.recording);
  EXPECT_EQ(status.files, 1u);
  EXPECT_EQ(status.messages, 3u);
  EXPECT_EQ(status.dropped_full + status.dropped_failed + status.dropped_invalid, 0u);

  const auto paths = files();
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_EQ(paths[0].filename().string().substr(0, 3), "gw-");
  EXPECT_EQ(paths[0].extension(), ".mcap");
  const McapFile file = read(paths[0]);
  EXPECT_FALSE(file.truncated);
  ASSERT_TRUE(file.summary.has_value());
  ASSERT_EQ(file.messages.size(), 3u);
  // One MCAP channel per channel, source segment and origin; the topic is the channel's name.
  ASSERT_EQ(file.channels.size(), 3u);
  std::set<std::string> seen;
  for (const McapChannel& c : file.channels)
    seen.insert(c.topic + "|" + c.message_encoding + "|" + c.metadata.at("segment") + "|" + c.metadata.at("origin"));
  EXPECT_EQ(seen, (std::set<std::string>{"obstacle|x-cosmic-bytes|body-can|a1", "obstacle|x-cosmic-bytes|lan|b2",
                                         "range|json|lan|a1"}));
  EXPECT_EQ(file.channels[0].metadata.at("subject"), "0x10");
  ASSERT_EQ(file.schemas.size(), 1u);
  EXPECT_EQ(file.schemas[0].name, "range");
  EXPECT_EQ(file.schemas[0].encoding, "jsonschema");
  EXPECT_EQ(std::string(file.schemas[0].data.begin(), file.schemas[0].data.end()), R"({"type":"object"})");

  EXPECT_EQ(file.messages[0].sequence, 7u);
  EXPECT_EQ(file.messages[0].publish_time, 1'000u);
  EXPECT_EQ(file.messages[0].data, obstacle);
  EXPECT_EQ(file.messages[1].sequence, 8u);
  EXPECT_EQ(file.messages[2].sequence, 9u);
  EXPECT_EQ(file.messages[2].publish_time, 3'000u);
  EXPECT_EQ(std::string(file.messages[2].data.begin(), file.messages[2].data.end()), R"({"distance":1.5})");
  for (const McapMessage& m : file.messages) {
    // Arrival on this host's UTC clock, within the test's run.
    EXPECT_GE(static_cast<std::int64_t>(m.log_time), started - 1'000'000'000);
    EXPECT_LE(static_cast<std::int64_t>(m.log_time), utc_now());
  }
}

// typed_encoding: cdr. A type with a CDR form is recorded as the XCDR1 sample ROS 2 writes, with
// its ROS 2 message definition; one without (a conditional field) as JSON, and the reason is given.
TEST_F(RecorderTest, ATypedChannelIsRecordedAsCdrWithItsRos2MessageDefinition) {
  RecordedChannel typed;
  typed.id = 2;
  typed.name = "range";
  EXPECT_EQ(set_typed_encoding(typed, distance_type(), TypedEncoding::cdr), std::nullopt);
  ASSERT_TRUE(typed.cdr);
  EXPECT_FALSE(typed.json);
  RecordedChannel multiplexed;
  multiplexed.id = 3;
  multiplexed.name = "status";
  ChannelType conditional = distance_type();
  conditional.fields.insert(conditional.fields.begin(),
                            TypeField{"mode", FieldType{FieldType::Kind::scalar, ScalarKind::uint8, {}, 0, {}, {}}, "",
                                      std::nullopt, std::nullopt, std::nullopt});
  conditional.fields.back().present_when = FieldPresence{"mode", 1};
  const auto why_not = set_typed_encoding(multiplexed, conditional, TypedEncoding::cdr);
  ASSERT_TRUE(why_not.has_value());
  EXPECT_NE(why_not->find("field distance is conditional"), std::string::npos) << *why_not;
  EXPECT_TRUE(multiplexed.json);
  EXPECT_FALSE(multiplexed.cdr);

  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels({typed, multiplexed});
  recorder.set_segment_names({"lan"});
  ASSERT_TRUE(recorder.start().ok());
  recorder.offer(2, 0, header(0xA1, 1, 1'000), steady_now(), float_bytes(1.5f));
  std::vector<std::uint8_t> status_event{1};  // mode 1: distance present
  for (const std::uint8_t b : float_bytes(2.5f)) status_event.push_back(b);
  recorder.offer(3, 0, header(0xA1, 2, 2'000), steady_now(), status_event);
  recorder.stop();
  EXPECT_EQ(recorder.status().dropped_invalid, 0u);

  const auto paths = files();
  ASSERT_EQ(paths.size(), 1u);
  const McapFile file = read(paths[0]);
  ASSERT_EQ(file.channels.size(), 2u);
  ASSERT_EQ(file.schemas.size(), 2u);
  std::map<std::string, const McapSchema*> schemas;
  for (const McapSchema& s : file.schemas) schemas[s.encoding] = &s;
  ASSERT_TRUE(schemas.count("ros2msg") && schemas.count("jsonschema"));
  EXPECT_EQ(schemas["ros2msg"]->name, "cosmic/msg/Range");
  EXPECT_EQ(std::string(schemas["ros2msg"]->data.begin(), schemas["ros2msg"]->data.end()), "float32 distance # [m]\n");
  EXPECT_EQ(schemas["jsonschema"]->name, "status");
  ASSERT_EQ(file.messages.size(), 2u);
  for (const McapChannel& c : file.channels) {
    const McapMessage& m = *std::find_if(file.messages.begin(), file.messages.end(),
                                         [&](const McapMessage& x) { return x.channel_id == c.id; });
    if (c.topic == "range") {
      EXPECT_EQ(c.message_encoding, "cdr");
      EXPECT_EQ(c.schema_id, schemas["ros2msg"]->id);
      // CDR_LE encapsulation, then the float32 1.5 little-endian.
      EXPECT_EQ(m.data, (std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0xc0, 0x3f}));
    } else {
      EXPECT_EQ(c.message_encoding, "json");
      EXPECT_EQ(std::string(m.data.begin(), m.data.end()), R"({"mode":1,"distance":2.5})");
    }
  }
}

TEST_F(RecorderTest, FilesRotateBySizeAndEachIsWhole) {
  spec_.rotate_size = 1 << 20;
  spec_.compression = RecordCompression::none;  // the size grows as the events do
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  recorder.set_segment_names({"body-can"});
  ASSERT_TRUE(recorder.start().ok());
  const std::vector<std::uint8_t> payload(1000, 0x5a);
  constexpr std::uint32_t kEvents = 3000;  // about 3 MB
  for (std::uint32_t n = 1; n <= kEvents; ++n) {
    recorder.offer(1, 0, header(1, n, n), steady_now(), payload);
    // Paced by what the writer has taken, so the queue never fills: every event is written.
    while (recorder.status().queued_bytes > recorder.status().queue_bytes / 2) std::this_thread::yield();
  }
  recorder.stop();
  EXPECT_EQ(recorder.status().dropped_full, 0u);
  const auto paths = files();
  ASSERT_GE(paths.size(), 3u);
  std::uint32_t next = 1;
  for (const auto& path : paths) {
    const McapFile file = read(path);
    EXPECT_FALSE(file.truncated) << path;
    EXPECT_TRUE(file.summary.has_value()) << path;
    for (const McapMessage& m : file.messages) EXPECT_EQ(m.sequence, next++);
    EXPECT_LE(fs::file_size(path), (1u << 20) + 64 * 1024) << path;
  }
  EXPECT_EQ(next, kEvents + 1) << "every event, in order, across the files";
  EXPECT_EQ(recorder.status().files, paths.size());
}

// A cosmicd restarted within the same second finds its first names taken: it numbers on, never
// overwriting (nor failing on) another's file.
TEST_F(RecorderTest, ANameTakenWithinTheSameSecondIsSkipped) {
  fs::create_directories(spec_.directory);
  const std::int64_t now = utc_now();
  for (std::int64_t second = 0; second < 3; ++second) {
    for (std::uint64_t n = 1; n <= 3; ++n) {
      const std::string name = recorder_detail::recording_file_name("gw", now + second * 1'000'000'000, n, ".mcap");
      std::ofstream(fs::path(spec_.directory) / name) << "";
    }
  }
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  ASSERT_TRUE(recorder.start().ok());
  const std::string file = recorder.status().file;
  recorder.stop();
  EXPECT_EQ(file.substr(file.size() - 7), "-4.mcap") << file;
  for (const auto& path : files()) {
    if (path.string() != file) {
      EXPECT_EQ(fs::file_size(path), 0u) << path << " was overwritten";
    }
  }
}

TEST_F(RecorderTest, ADirectoryThatCannotBeWrittenRefusesStartWithTheReason) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "plain-file") << "not a directory";
  spec_.directory = (dir_ / "plain-file" / "rec").string();
  Recorder recorder(spec_, "gw", log_);
  const auto started = recorder.start();
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.error().text.find("cannot make the recording directory " + spec_.directory), std::string::npos)
      << started.error().text;
  EXPECT_FALSE(recorder.status().recording);
}

TEST_F(RecorderTest, TooLongAndUnknownEventsAreCountedNotWritten) {
  spec_.memory = 1 << 20;
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  ASSERT_TRUE(recorder.start().ok());
  const std::vector<std::uint8_t> huge(300 * 1024, 1);  // beyond a quarter of the 1 MiB queue
  recorder.offer(1, 0, header(1, 1, 1), steady_now(), huge);
  recorder.offer(99, 0, header(1, 2, 1), steady_now(), std::vector<std::uint8_t>{1});    // not a recorded channel
  recorder.offer(2, 0, header(1, 3, 1), steady_now(), std::vector<std::uint8_t>{1, 2});  // not a float32
  recorder.offer(1, 0, header(1, 4, 1), steady_now(), std::vector<std::uint8_t>{1});
  recorder.stop();
  const RecorderStatus status = recorder.status();
  EXPECT_EQ(status.dropped_full, 1u);
  EXPECT_EQ(status.dropped_invalid, 2u);
  EXPECT_EQ(status.messages, 1u);
  const McapFile file = read(files().at(0));
  ASSERT_EQ(file.messages.size(), 1u);
  EXPECT_EQ(file.messages[0].sequence, 4u);
}

// A stop finds the writer far behind (events offered much faster than it writes them): it still
// writes every event queued before it, not only the writer's usual budget of one pass.
TEST_F(RecorderTest, AStopWritesEverythingQueuedBeforeIt) {
  spec_.chunk_size = 1 << 20;
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  ASSERT_TRUE(recorder.start().ok());
  constexpr std::uint32_t kEvents = 200'000;  // about 11 MB queued, more than one pass takes
  const std::vector<std::uint8_t> payload(8, 0x5a);
  for (std::uint32_t n = 1; n <= kEvents; ++n) recorder.offer(1, 0, header(1, n, n), steady_now(), payload);
  recorder.stop();
  const RecorderStatus status = recorder.status();
  EXPECT_EQ(status.dropped_full, 0u);
  EXPECT_EQ(status.messages, kEvents);
  const McapFile file = read(files().at(0));
  ASSERT_EQ(file.messages.size(), kEvents);
  EXPECT_EQ(file.messages.back().sequence, kEvents);
}

// Files may grow to `bytes` while it lives (write(2) then fails with EFBIG, SIGXFSZ ignored).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    saved_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limited = saved_;
    limited.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limited);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, saved_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*saved_handler_)(int) = SIG_DFL;
};

// A chunk the file cannot take (its write fails) loses every event in it: each counts as not
// written, none as written.
TEST_F(RecorderTest, EveryEventOfAChunkThatFailedToWriteCountsAsNotWritten) {
  spec_.chunk_size = 4096;
  spec_.compression = RecordCompression::none;  // the chunk stays larger than the limit
  Recorder recorder(spec_, "gw", log_);
  recorder.set_channels(channels());
  const FileSizeLimit limit(2048);  // the header and first metadata fit, the first chunk does not
  ASSERT_TRUE(recorder.start().ok());
  constexpr std::uint32_t kEvents = 50;  // about 7 kB of Message records: the first chunk closes
  const std::vector<std::uint8_t> payload(100, 0x5a);
  for (std::uint32_t n = 1; n <= kEvents; ++n) recorder.offer(1, 0, header(1, n, n), steady_now(), payload);
  recorder.stop();
  const RecorderStatus status = recorder.status();
  EXPECT_NE(status.last_error.find("cannot write"), std::string::npos) << status.last_error;
  EXPECT_EQ(status.messages, 0u);
  EXPECT_EQ(status.dropped_failed, kEvents);
  EXPECT_EQ(status.dropped_full + status.dropped_invalid, 0u);
}

}  // namespace
}  // namespace cosmic

namespace cosmic {
namespace {

// `cosmicctl record info`'s figures (cosmic/recording_info.hpp) on a file written here: per stream
// its count, bytes, span, largest gap and the sequence numbers skipped (a repeat or a lower number,
// as after a publisher's restart, skips none); the closing drops; a file cut short counts what it
// keeps.
TEST(RecordingInfo, CountsStreamsGapsMissingNumbersAndDrops) {
  std::vector<std::uint8_t> bytes;
  auto writer = McapWriter::open({}, [&](std::span<const std::uint8_t> b) -> Result<void> {
    bytes.insert(bytes.end(), b.begin(), b.end());
    return {};
  });
  ASSERT_TRUE(writer);
  McapWriter& w = writer.value();
  ASSERT_TRUE(w.add_metadata("cosmic", {{"gateway", "gw"}}));
  const auto a = w.add_channel(0, "obstacle", "x-cosmic-bytes", {{"segment", "field"}, {"origin", "a1"}});
  const auto b = w.add_channel(0, "obstacle", "x-cosmic-bytes", {{"segment", "lan"}, {"origin", "b2"}});
  ASSERT_TRUE(a && b);
  const std::vector<std::uint8_t> four{1, 2, 3, 4};
  // Stream a: numbers 1 2 4 7 3 (3 after 7: skips none) at 1, 2, 3, 10, 11 s.
  const std::uint32_t numbers[] = {1, 2, 4, 7, 3};
  const std::uint64_t seconds[] = {1, 2, 3, 10, 11};
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(w.write_message(a.value(), numbers[i], seconds[i] * 1'000'000'000, 0, four));
  ASSERT_TRUE(w.write_message(b.value(), 5, 4'000'000'000, 0, std::vector<std::uint8_t>{9}));
  ASSERT_TRUE(w.add_metadata("cosmic.closing", {{"dropped_queue_full", "3"}}));
  ASSERT_TRUE(w.finish());

  const auto info = recording_info(bytes);
  ASSERT_TRUE(info) << info.error().text;
  const RecordingInfo& i = info.value();
  EXPECT_TRUE(i.whole);
  EXPECT_EQ(i.gateway, "gw");
  EXPECT_EQ(i.messages, 6u);
  EXPECT_EQ(i.start_ns, 1'000'000'000u);
  EXPECT_EQ(i.end_ns, 11'000'000'000u);
  EXPECT_EQ(i.closing.at("dropped_queue_full"), "3");
  ASSERT_EQ(i.streams.size(), 2u);
  const RecordedStream& s = i.streams[0];
  EXPECT_EQ(s.segment, "field");
  EXPECT_EQ(s.origin, "a1");
  EXPECT_EQ(s.messages, 5u);
  EXPECT_EQ(s.bytes, 20u);
  EXPECT_EQ(s.largest_gap_ns, 7'000'000'000u);
  EXPECT_EQ(s.missing, 1u + 2u);  // 3 between 2 and 4; 5 and 6 between 4 and 7
  EXPECT_DOUBLE_EQ(s.rate_hz(), 4.0 / 10.0);
  EXPECT_EQ(i.streams[1].messages, 1u);
  EXPECT_EQ(i.streams[1].rate_hz(), 0.0);

  // Cut inside the summary: everything of the data section is still counted.
  const auto cut = recording_info(std::span<const std::uint8_t>(bytes).first(bytes.size() - 40));
  ASSERT_TRUE(cut) << cut.error().text;
  EXPECT_FALSE(cut.value().whole);
  EXPECT_EQ(cut.value().messages, 6u);
  const std::vector<std::uint8_t> garbage{'n', 'o', 't', ' ', 'm', 'c', 'a', 'p', 0, 0, 0, 0};
  EXPECT_FALSE(recording_info(garbage));
}

}  // namespace
}  // namespace cosmic

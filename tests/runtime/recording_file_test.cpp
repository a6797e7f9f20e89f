// One recording file (recorder_detail::RecordingFile): a channel whose type a replacement changed,
// keeping its channel id, gets a schema and MCAP channel of its own, so each message reads with the
// schema it was written for; a channel table rebuilt with the same type keeps writing to the same
// MCAP channel.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cosmic/mcap_reader.hpp"
#include "cosmic/recorder.hpp"
#include "recording_file.hpp"

namespace cosmic {
namespace {

namespace fs = std::filesystem;

ChannelType one_scalar_type(ScalarKind kind) {
  FieldType scalar;
  scalar.kind = FieldType::Kind::scalar;
  scalar.scalar = kind;
  ChannelType type;
  type.fields.push_back(TypeField{"range", scalar, "m", std::nullopt, std::nullopt, std::nullopt});
  return type;
}

RecordedChannel recorded_as(ScalarKind kind) {
  RecordedChannel channel;
  channel.id = 7;
  channel.name = "range";
  EXPECT_FALSE(set_typed_encoding(channel, one_scalar_type(kind), TypedEncoding::cdr).has_value());
  return channel;
}

TEST(RecordingFileTest, AChannelWhoseTypeChangedGetsASchemaAndChannelOfItsOwn) {
  const fs::path dir = fs::path(testing::TempDir()) / ("recording_file_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "retyped.mcap").string();
  RecordingSpec spec;
  auto file = recorder_detail::RecordingFile::create(path, spec, "gw", 1'000'000'000);
  ASSERT_TRUE(file) << file.error().text;
  const RecordedChannel before = recorded_as(ScalarKind::float32);
  const RecordedChannel after = recorded_as(ScalarKind::int16);
  const RecordedChannel after_rebuilt = recorded_as(ScalarKind::int16);  // a later table, same type
  ASSERT_NE(before.form, after.form);
  ASSERT_EQ(after.form, after_rebuilt.form);
  const std::string segment = "lan";
  const std::vector<std::vector<std::uint8_t>> contents{{1, 2, 3, 4}, {5, 6}, {7, 8}};
  const RecordedChannel* tables[] = {&before, &after, &after_rebuilt};
  for (std::size_t i = 0; i < 3; ++i) {
    recorder_detail::TakenEvent event;
    event.channel = 7;
    event.segment = &segment;
    event.origin = 0xA1;
    event.sequence = static_cast<std::uint32_t>(i + 1);
    event.arrival_ns = 2'000'000'000 + static_cast<std::int64_t>(i);
    event.contents = contents[i];
    const auto written = file.value()->write(*tables[i], event);
    ASSERT_TRUE(written && written.value());
  }
  ASSERT_TRUE(file.value()->finish({}));
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto read = read_mcap(bytes);
  ASSERT_TRUE(read) << read.error().text;
  const McapFile& mcap = read.value();
  ASSERT_EQ(mcap.schemas.size(), 2u);
  EXPECT_NE(mcap.schemas[0].data, mcap.schemas[1].data);
  ASSERT_EQ(mcap.channels.size(), 2u);
  EXPECT_EQ(mcap.channels[0].topic, "range");
  EXPECT_EQ(mcap.channels[1].topic, "range");
  EXPECT_EQ(mcap.channels[0].schema_id, mcap.schemas[0].id);
  EXPECT_EQ(mcap.channels[1].schema_id, mcap.schemas[1].id);
  ASSERT_EQ(mcap.messages.size(), 3u);
  EXPECT_EQ(mcap.messages[0].channel_id, mcap.channels[0].id);
  EXPECT_EQ(mcap.messages[1].channel_id, mcap.channels[1].id);
  EXPECT_EQ(mcap.messages[2].channel_id, mcap.channels[1].id);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cosmic

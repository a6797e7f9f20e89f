// Persistence of runtime bindings: round trip, atomic replacement, corrupted files.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "binding_store.hpp"
#include "cosmic/config_loader.hpp"

namespace {

class BindingStoreTest : public ::testing::Test {
 protected:
  BindingStoreTest() : dir(std::filesystem::temp_directory_path() / ("cosmic-state-" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(dir);
    path = (dir / "bindings.json").string();
  }
  ~BindingStoreTest() override { std::filesystem::remove_all(dir); }
  void write(const std::string& text) {
    std::filesystem::create_directories(dir);
    std::ofstream(path) << text;
  }
  std::filesystem::path dir;
  std::string path;
};

TEST_F(BindingStoreTest, MissingFileIsAnEmptyState) {
  const auto loaded = cosmicd::load_binding_state(path);
  EXPECT_TRUE(loaded.error.empty());
  EXPECT_TRUE(loaded.state.bound.empty());
}

TEST_F(BindingStoreTest, RoundTripAndNoTemporaryLeftBehind) {
  cosmicd::BindingState state;
  state.bound.push_back({"extra", "{name: extra}"});
  state.unbound.push_back("speed");
  ASSERT_EQ(cosmicd::save_binding_state(path, state), "");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const auto loaded = cosmicd::load_binding_state(path);
  EXPECT_TRUE(loaded.error.empty());
  ASSERT_EQ(loaded.state.bound.size(), 1u);
  EXPECT_EQ(loaded.state.bound[0].name, "extra");
  EXPECT_EQ(loaded.state.unbound, std::vector<std::string>{"speed"});
}

TEST_F(BindingStoreTest, CorruptedFilesGiveAClearErrorNotACrash) {
  for (const char* text : {"{not json", "[]", R"({"version":99,"bound":[],"unbound":[]})",
                           R"({"version":1,"bound":[{"name":1}],"unbound":[]})", ""}) {
    write(text);
    const auto loaded = cosmicd::load_binding_state(path);
    EXPECT_FALSE(loaded.error.empty()) << text;
    EXPECT_NE(loaded.error.find(path), std::string::npos);
    EXPECT_TRUE(loaded.state.bound.empty());
  }
}

// Issue 22, item 10: a state file cosmicd cannot use is moved aside before anything can overwrite
// the runtime bindings it may still hold; each bad file gets its own name.
TEST_F(BindingStoreTest, AnUnusableFileIsSetAsideNeverOverwritten) {
  write("{\"version\":1,\"bound\":[{\"name\":\"extra\",\"yaml\":\"{name: extra}\"}],\"unbound\":[");  // truncated
  ASSERT_FALSE(cosmicd::load_binding_state(path).error.empty());
  const auto first = cosmicd::set_aside_state_file(path);
  ASSERT_EQ(first.error, "");
  EXPECT_EQ(first.moved_to, path + ".corrupt-1");
  EXPECT_FALSE(std::filesystem::exists(path));
  std::ifstream kept(first.moved_to);
  EXPECT_NE(std::string(std::istreambuf_iterator<char>(kept), {}).find("extra"), std::string::npos);
  // A save now writes a fresh file and leaves the set-aside one alone.
  ASSERT_EQ(cosmicd::save_binding_state(path, cosmicd::BindingState{}), "");
  EXPECT_TRUE(std::filesystem::exists(first.moved_to));
  write("garbage");
  const auto second = cosmicd::set_aside_state_file(path);
  EXPECT_EQ(second.moved_to, path + ".corrupt-2");
  const auto missing = cosmicd::set_aside_state_file(path);
  EXPECT_EQ(missing.moved_to, "") << "nothing there: nothing moved";
  EXPECT_EQ(missing.error, "");
}

TEST(ChannelYamlTest, ChannelSurvivesTheRoundTripThroughYaml) {
  const auto config = cosmic::parse_config(R"(
segments: [{name: a, type: dds}, {name: b, type: lcm}]
channels:
  - {name: c, subject: 0x42, class: srt, max_rate: 300Hz, reaction_time: 5ms, omission_degree: 2,
     temp_validity: 1s, payload: 12B, etag: 200, encoding: raw, publishers: [a], subscribers: [b]}
)",
                                           "t.yaml");
  ASSERT_TRUE(config.ok());
  const std::string yaml = cosmic::channel_to_yaml(config.config.channels[0]);
  const auto back = cosmic::parse_channels(yaml, "state", config.config);
  ASSERT_TRUE(back.ok()) << back.errors[0].to_string();
  ASSERT_EQ(back.channels.size(), 1u);
  EXPECT_EQ(back.channels[0], config.config.channels[0]);
}

TEST_F(BindingStoreTest, SymlinksPlantedForTheTemporaryFileAreNeverFollowed) {
  std::filesystem::create_directories(dir);
  const std::string victim = (dir / "victim").string();
  std::ofstream(victim) << "untouched\n";
  std::filesystem::create_symlink(victim, path + ".tmp");  // the name the old code wrote through
  cosmicd::BindingState state;
  state.bound.push_back({"extra", "{name: extra}"});
  ASSERT_EQ(cosmicd::save_binding_state(path, state), "");
  std::ifstream in(victim);
  std::string content;
  std::getline(in, content);
  EXPECT_EQ(content, "untouched");
  EXPECT_TRUE(std::filesystem::is_symlink(path + ".tmp"));
  EXPECT_EQ(cosmicd::load_binding_state(path).state.bound.size(), 1u);
}

TEST_F(BindingStoreTest, AFifoADeviceAndAHugeFileAreRefusedWithoutBlocking) {
  std::filesystem::create_directories(dir);
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  const auto fifo = cosmicd::load_binding_state(path);  // without O_NONBLOCK this waits for a writer forever
  EXPECT_NE(fifo.error.find("not a regular file"), std::string::npos) << fifo.error;
  std::filesystem::remove(path);
  const auto device = cosmicd::load_binding_state("/dev/zero");
  EXPECT_NE(device.error.find("not a regular file"), std::string::npos) << device.error;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, static_cast<off_t>(cosmicd::kMaxStateFileBytes + 1)), 0);  // sparse: costs no disk
  ::close(fd);
  const auto huge = cosmicd::load_binding_state(path);
  EXPECT_NE(huge.error.find("above the limit"), std::string::npos) << huge.error;
}

TEST_F(BindingStoreTest, AFailedSaveSaysWhy) {
  std::filesystem::create_directories(dir);
  std::ofstream((dir / "file").string()) << "x";
  EXPECT_NE(cosmicd::save_binding_state((dir / "file" / "bindings.json").string(), {}), "");
}

TEST(BindingEntryTest, AnEntryMustDefineExactlyTheChannelItIsNamedAfter) {
  const auto config =
      cosmic::parse_config("segments: [{name: a, type: dds}, {name: b, type: lcm}]\nchannels: []\n", "t.yaml");
  const auto parse = [&](const char* yaml) { return cosmic::parse_channels(yaml, "state", config.config).channels; };
  const char* other = "{name: other, subject: 7, class: nrt, publishers: [a], subscribers: [b]}";
  EXPECT_EQ(cosmicd::check_binding_entry({"other", other}, parse(other)), "");
  EXPECT_NE(cosmicd::check_binding_entry({"speed", other}, parse(other)), "");
  const char* two =
      "[{name: speed, subject: 7, class: nrt, publishers: [a], subscribers: [b]},"
      " {name: other, subject: 8, class: nrt, publishers: [a], subscribers: [b]}]";
  EXPECT_NE(cosmicd::check_binding_entry({"speed", two}, parse(two)), "");
}

}  // namespace

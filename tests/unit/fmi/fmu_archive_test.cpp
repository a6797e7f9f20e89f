// FMU archives (cosmic/fmu_archive.hpp), written by the test with libzip around the shared library
// the build compiles from fmi_test_model.c: read without extracting; opened, the platform's binary
// and the resources extracted and the library loadable; refused: not a zip, no description, no
// binary for this platform (naming the ones there are), a zip-slip entry, a symbolic link, a
// description with problems, a directory or FIFO in the FMU's place, a work directory that is not empty.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "cosmic/build_paths.hpp"
#include "cosmic/fmu_archive.hpp"
#include "fmu_test_support.hpp"

namespace cosmic::fmi {
namespace {

namespace fs = std::filesystem;

std::string errors_of(const std::vector<std::string>& errors) {
  std::string out;
  for (const auto& e : errors) out += e + "\n";
  return out;
}

class FmuArchive : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("fmu_archive_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    library_ = test::file_bytes(build_paths::fmi_test_model);
    ASSERT_FALSE(library_.empty());
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string fmu(const std::string& name, const std::vector<test::ZipEntry>& entries) {
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(test::write_zip(path, entries));
    return path;
  }

  std::vector<test::ZipEntry> plant(const std::string& platform = "linux64") {
    return {{"modelDescription.xml", test::kFmi2Description},
            {"binaries/" + platform + "/Plant.so", library_},
            {"binaries/win64/Plant.dll", "MZ"},
            {"resources/table.csv", "t,v\n0,1\n"},
            {"documentation/index.html", "<html/>"}};
  }

  fs::path dir_;
  std::string library_;
};

TEST_F(FmuArchive, ReadFindsTheBinaryForThisPlatformWithoutExtracting) {
  const FmuReadResult r = read_fmu(fmu("plant.fmu", plant()));
  ASSERT_TRUE(r.ok()) << errors_of(r.errors);
  EXPECT_EQ(r.contents.binary_entry, "binaries/linux64/Plant.so");
  EXPECT_EQ(r.contents.description.model_name, "Plant");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);  // the FMU alone
  std::vector<test::ZipEntry> every = {{"modelDescription.xml", test::kFmi3Description},
                                       {"binaries/x86_64-linux/Every.so", library_}};
  const FmuReadResult three = read_fmu(fmu("every.fmu", every));
  ASSERT_TRUE(three.ok()) << errors_of(three.errors);
  EXPECT_EQ(three.contents.binary_entry, "binaries/x86_64-linux/Every.so");
}

TEST_F(FmuArchive, OpenExtractsTheBinaryAndResourcesAndTheLibraryLoads) {
  const fs::path work = dir_ / "work";
  const FmuOpenResult r = open_fmu(fmu("plant.fmu", plant()), work.string());
  ASSERT_TRUE(r.ok()) << errors_of(r.errors);
  EXPECT_EQ(r.fmu.binary, (work / "binaries/linux64/Plant.so").string());
  EXPECT_EQ(r.fmu.resources, (work / "resources").string());
  EXPECT_EQ(test::file_bytes(r.fmu.binary), library_);
  EXPECT_EQ(test::file_bytes((work / "resources/table.csv").string()), "t,v\n0,1\n");
  EXPECT_FALSE(fs::exists(work / "binaries/win64"));  // other platforms stay in the archive
  EXPECT_FALSE(fs::exists(work / "documentation"));   // and so does the rest
  void* handle = ::dlopen(r.fmu.binary.c_str(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(handle, nullptr) << ::dlerror();
  using Version = const char* (*)();
  const auto version = reinterpret_cast<Version>(::dlsym(handle, "fmi2GetVersion"));
  ASSERT_NE(version, nullptr);
  EXPECT_STREQ(version(), "2.0");
  ::dlclose(handle);

  // A second FMU into the same, now full, directory is refused: nothing is overwritten.
  const FmuOpenResult again = open_fmu(dir_ / "plant.fmu", work.string());
  EXPECT_NE(errors_of(again.errors).find("the directory is not empty"), std::string::npos) << errors_of(again.errors);
}

TEST_F(FmuArchive, EveryRefusalSaysWhy) {
  std::ofstream(dir_ / "text.fmu") << "not a zip";
  ASSERT_EQ(::mkfifo((dir_ / "pipe.fmu").c_str(), 0600), 0);
  auto no_linux = plant("darwin64");
  auto slip = plant();
  slip.push_back({"resources/../../escaped.txt", "x"});
  auto absolute = plant();
  absolute.push_back({"/tmp/absolute.txt", "x"});
  auto link = plant();
  link.push_back({"resources/passwd", "/etc/passwd", true});
  auto bad_description = plant();
  bad_description[0].bytes =
      "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"M\" guid=\"g\">\n</fmiModelDescription>";
  struct Case {
    std::string path;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {(dir_ / "text.fmu").string(), "text.fmu is not an FMU: not a zip archive"},
      {(dir_ / "missing.fmu").string(), "cannot open " + (dir_ / "missing.fmu").string() + ": No such file"},
      {dir_.string(), "is not an FMU: not a regular file"},
      {(dir_ / "pipe.fmu").string(), "pipe.fmu is not an FMU: not a regular file"},
      {fmu("empty.fmu", {{"README", "x"}}), "empty.fmu is not an FMU: it holds no modelDescription.xml"},
      {fmu("mac.fmu", no_linux),
       "mac.fmu has no binary for this platform (binaries/linux64/Plant.so); its platforms: darwin64, win64"},
      {fmu("source.fmu", {{"modelDescription.xml", test::kFmi2Description}, {"sources/plant.c", ""}}),
       "its platforms: none (no binaries/ directory"},
      {fmu("slip.fmu", slip), "entry 'resources/../../escaped.txt' would leave the directory"},
      {fmu("absolute.fmu", absolute), "entry '/tmp/absolute.txt' would leave the directory"},
      {fmu("link.fmu", link), "entry 'resources/passwd' is a symbolic link"},
      {fmu("bad.fmu", bad_description), "bad.fmu: modelDescription.xml:1: no <CoSimulation> element"},
  };
  for (const Case& c : cases) {
    const FmuOpenResult r = open_fmu(c.path, (dir_ / "work").string());
    EXPECT_FALSE(r.ok()) << c.expected;
    EXPECT_NE(errors_of(r.errors).find(c.expected), std::string::npos) << "want: " << c.expected << "\ngot:\n"
                                                                       << errors_of(r.errors);
    EXPECT_FALSE(fs::exists(dir_ / "escaped.txt"));
    EXPECT_FALSE(fs::exists(dir_ / "work/resources/passwd"));
  }
}

TEST(FmuEntryNames, OnlyRelativeNamesWithoutClimbingAreSafe) {
  for (const char* name : {"binaries/linux64/a.so", "resources/", "a..b/c", "resources/x/..y"})
    EXPECT_TRUE(safe_entry_name(name)) << name;
  for (const char* name : {"", "/etc/passwd", "..", "../a", "a/../../b", "a/..", "a\\..\\b"})
    EXPECT_FALSE(safe_entry_name(name)) << name;
}

}  // namespace
}  // namespace cosmic::fmi

// An FMU file (a zip archive, FMI 2.0 and 3.x; issue 38, docs/fmu.md): its modelDescription.xml read,
// the shared library for this platform found, and, for a runner, the library and the resources
// extracted into a directory of the caller's.
//
// Files are read with libzip; nothing here loads the library. Never throws.
// Threads: no shared state; any thread, one archive per call.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/fmi_description.hpp"

namespace cosmic::fmi {

// Bounds on what one archive may cost: its entries, one entry's bytes, and everything extracted.
inline constexpr std::size_t kMaxArchiveEntries = 100'000;
inline constexpr std::uint64_t kMaxExtractedBytes = 1ull << 30;

// The directory of binaries/ holding this platform's libraries: FMI 2.0 "linux64", FMI 3.0
// "x86_64-linux" (on x86-64; FMI 3.0 "aarch64-linux" on 64-bit ARM, where FMI 2.0 names none: empty).
std::string_view platform_directory(FmiVersion version);

// Whether an archive entry's name is safe to extract below a directory: relative, no ".." part, no
// backslash, not empty.
bool safe_entry_name(std::string_view name);

struct FmuContents {
  FmuDescription description;
  std::string binary_entry;  // in the archive: "binaries/x86_64-linux/Plant.so"
};

struct FmuReadResult {
  FmuContents contents;             // meaningful only when errors is empty
  std::vector<std::string> errors;  // each says the file and what is wrong; description problems with their line
  bool ok() const { return errors.empty(); }
};

// Reads the archive at `path` without extracting anything: its modelDescription.xml parsed, the
// binary for this platform present. Refused: a file that is not a zip archive, an entry whose name
// is not safe (above), a symbolic link, more than kMaxArchiveEntries entries, no modelDescription.xml,
// a description with problems, no <modelIdentifier>.so under this platform's directory (the error
// names the platforms the FMU has).
FmuReadResult read_fmu(const std::string& path);

struct OpenedFmu {
  FmuDescription description;
  std::string binary;     // the extracted shared library: WORK_DIR/binaries/PLATFORM/ID.so
  std::string resources;  // WORK_DIR/resources (created, empty when the FMU has none)
};

struct FmuOpenResult {
  OpenedFmu fmu;  // meaningful only when errors is empty
  std::vector<std::string> errors;
  bool ok() const { return errors.empty(); }
};

// read_fmu(), then the archive's binaries/PLATFORM/ and resources/ extracted into `work_dir`
// (created when missing; it must be empty: the caller owns it and removes it). Extracted bytes stay
// within kMaxExtractedBytes; a file already there is never overwritten nor followed.
FmuOpenResult open_fmu(const std::string& path, const std::string& work_dir);

}  // namespace cosmic::fmi

// A whole file mapped read-only (mmap), unmapped with the object: how recordings are read (the
// configuration's replay segments, `cosmicctl record info`, the replay adapter) without copying
// them into memory. A file cut short under the mapping (truncated in place) makes reading the lost
// pages fault (SIGBUS): replace such files by renaming them (docs/recording.md).
//
// Threads: immutable once made; any thread reads bytes().
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "cosmic/result.hpp"

namespace cosmic {

class MappedFile {
 public:
  // A regular, non-empty file; else the reason ("cannot open PATH: ...", "PATH is empty").
  static Result<std::unique_ptr<MappedFile>> open(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::span<const std::uint8_t> bytes() const { return {data_, size_}; }

 private:
  MappedFile(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  const std::uint8_t* data_;
  std::size_t size_;
};

}  // namespace cosmic

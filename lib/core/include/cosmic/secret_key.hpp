// Key material the configuration names (issue 36): an LCM segment's `auth: {key_file}`, a CAN
// hop's `secoc: {key_file}`. A key file holds the key as hexadecimal digits, as
// `openssl rand -hex 32 > FILE` writes it (white space between and around them is ignored); the
// configuration loader reads it, refuses a file group or others may read or write, and keeps the
// bytes here. The bytes are wiped when a SecretKey goes away.
//
// Threads: a value; any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "cosmic/result.hpp"

namespace cosmic {

class SecretKey {
 public:
  SecretKey() = default;
  explicit SecretKey(std::vector<std::uint8_t> bytes) : bytes_(std::move(bytes)) {}
  SecretKey(const SecretKey&) = default;
  SecretKey& operator=(const SecretKey& other);
  SecretKey(SecretKey&& other) noexcept;
  SecretKey& operator=(SecretKey&& other) noexcept;
  ~SecretKey();

  std::span<const std::uint8_t> bytes() const noexcept { return bytes_; }
  std::size_t size() const noexcept { return bytes_.size(); }
  bool empty() const noexcept { return bytes_.empty(); }
  friend bool operator==(const SecretKey&, const SecretKey&) = default;

 private:
  void wipe() noexcept;
  std::vector<std::uint8_t> bytes_;
};

// The key a key file's text holds: hexadecimal digits, an even number of them, from `min_bytes`
// to `max_bytes` bytes; else why not (never quoting the text).
Result<SecretKey> parse_key_text(std::string_view text, std::size_t min_bytes, std::size_t max_bytes);

// Why a key file of permission bits `mode` (st_mode) must not be used: group or others may read
// or write it. Ok otherwise.
Result<void> check_key_file_mode(unsigned mode);

}  // namespace cosmic

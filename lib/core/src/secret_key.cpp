#include "cosmic/secret_key.hpp"

#include <cstdio>
#include <string>

namespace cosmic {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

}  // namespace

SecretKey& SecretKey::operator=(const SecretKey& other) {
  if (this != &other) {
    wipe();
    bytes_ = other.bytes_;
  }
  return *this;
}

SecretKey::SecretKey(SecretKey&& other) noexcept : bytes_(std::move(other.bytes_)) { other.bytes_.clear(); }

SecretKey& SecretKey::operator=(SecretKey&& other) noexcept {
  if (this != &other) {
    wipe();
    bytes_ = std::move(other.bytes_);
    other.bytes_.clear();
  }
  return *this;
}

SecretKey::~SecretKey() { wipe(); }

void SecretKey::wipe() noexcept {
  // Through a volatile pointer: a store the compiler may not drop as dead.
  volatile std::uint8_t* p = bytes_.data();
  for (std::size_t i = 0; i < bytes_.size(); ++i) p[i] = 0;
}

Result<SecretKey> parse_key_text(std::string_view text, std::size_t min_bytes, std::size_t max_bytes) {
  std::vector<std::uint8_t> bytes;
  bytes.reserve(max_bytes);  // never reallocated: no copy of key bytes is left behind
  // Whatever is decoded of a text refused is wiped too.
  struct WipeOnReturn {
    std::vector<std::uint8_t>& bytes;
    ~WipeOnReturn() {
      volatile std::uint8_t* p = bytes.data();
      for (std::size_t i = 0; i < bytes.size(); ++i) p[i] = 0;
    }
  } wipe_on_return{bytes};
  int high = -1;
  std::size_t position = 0;
  for (const char c : text) {
    ++position;
    if (is_space(c)) {
      if (high >= 0)
        return Error{"a hexadecimal digit stands alone before the white space at byte " + std::to_string(position)};
      continue;
    }
    const int digit = hex_value(c);
    if (digit < 0) return Error{"byte " + std::to_string(position) + " is not a hexadecimal digit"};
    if (high < 0) {
      high = digit;
      continue;
    }
    if (bytes.size() == max_bytes) return Error{"more than " + std::to_string(max_bytes) + " bytes of key"};
    bytes.push_back(static_cast<std::uint8_t>(high << 4 | digit));
    high = -1;
  }
  if (high >= 0) return Error{"an odd number of hexadecimal digits"};
  if (bytes.size() < min_bytes) {
    return Error{std::to_string(bytes.size()) + " bytes of key, fewer than " + std::to_string(min_bytes) +
                 " (openssl rand -hex " + std::to_string(min_bytes) + " writes one)"};
  }
  return SecretKey(std::vector<std::uint8_t>(bytes));  // a copy: `bytes` is wiped on the way out
}

Result<void> check_key_file_mode(unsigned mode) {
  if ((mode & 077u) == 0) return {};
  char octal[8];
  std::snprintf(octal, sizeof octal, "%04o", mode & 07777u);
  return Error{std::string("group or others may read or write it (mode ") + octal + "; chmod 600 it)"};
}

}  // namespace cosmic

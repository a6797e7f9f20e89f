// Little-endian fields of MCAP records: appended to a byte vector, and read off a span by a cursor
// that never reads past its end (a short read sets a flag and yields zeros, so a parser checks
// once, after its last field, instead of at every field).
//
// Threads: plain values; any thread.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/mcap_records.hpp"

namespace cosmic::mcap_detail {

inline std::uint8_t opcode_byte(McapOpcode opcode) { return static_cast<std::uint8_t>(opcode); }

// `value` little-endian at `at`, which has room for it (records built in one piece: the hot path).
template <typename T>
inline void store_le(std::uint8_t* at, T value) noexcept {
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(at, &value, sizeof value);
  } else {
    for (std::size_t i = 0; i < sizeof value; ++i) at[i] = static_cast<std::uint8_t>(value >> (8 * i));
  }
}

inline void put_le(std::vector<std::uint8_t>& out, std::uint64_t value, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
inline void put_u8(std::vector<std::uint8_t>& out, std::uint8_t v) { out.push_back(v); }
inline void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) { put_le(out, v, 2); }
inline void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) { put_le(out, v, 4); }
inline void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) { put_le(out, v, 8); }
inline void put_raw(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}
inline void put_string(std::vector<std::uint8_t>& out, std::string_view s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}

// Overwrites the 8 bytes at `at` (a length written before its content was known).
inline void patch_u64(std::vector<std::uint8_t>& out, std::size_t at, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Starts a record: opcode and a length to patch; returns where the length sits.
inline std::size_t begin_record(std::vector<std::uint8_t>& out, std::uint8_t opcode) {
  put_u8(out, opcode);
  const std::size_t at = out.size();
  put_u64(out, 0);
  return at;
}
inline void end_record(std::vector<std::uint8_t>& out, std::size_t length_at) {
  patch_u64(out, length_at, out.size() - length_at - 8);
}

inline std::uint64_t get_le(std::span<const std::uint8_t> bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = bytes.size(); i-- > 0;) v = (v << 8) | bytes[i];
  return v;
}

class Cursor {
 public:
  explicit Cursor(std::span<const std::uint8_t> bytes) : rest_(bytes) {}

  bool failed() const { return failed_; }
  bool empty() const { return rest_.empty(); }
  std::span<const std::uint8_t> rest() const { return rest_; }

  std::uint8_t u8() { return static_cast<std::uint8_t>(get_le(take(1))); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(get_le(take(2))); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(get_le(take(4))); }
  std::uint64_t u64() { return get_le(take(8)); }
  // `count` bytes, or an empty span (and the flag) when fewer are left.
  std::span<const std::uint8_t> take(std::uint64_t count) {
    if (failed_ || count > rest_.size()) {
      failed_ = true;
      rest_ = {};
      return {};
    }
    const auto out = rest_.first(static_cast<std::size_t>(count));
    rest_ = rest_.subspan(static_cast<std::size_t>(count));
    return out;
  }
  std::span<const std::uint8_t> bytes32() { return take(u32()); }
  std::span<const std::uint8_t> bytes64() { return take(u64()); }
  std::string string() {
    const auto b = bytes32();
    return std::string(b.begin(), b.end());
  }

 private:
  std::span<const std::uint8_t> rest_;
  bool failed_ = false;
};

}  // namespace cosmic::mcap_detail

// Bytes as the lowercase hex text the CDR peers exchange with their Cyclone counterparts (and back).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace cosmic::peer {

inline std::string hex(const std::vector<std::uint8_t>& bytes) {
  std::string out;
  char two[3];
  for (const std::uint8_t b : bytes) {
    std::snprintf(two, sizeof two, "%02x", b);
    out += two;
  }
  return out;
}

// Pairs of hex digits; a trailing odd digit is ignored.
inline std::vector<std::uint8_t> unhex(const std::string& text) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < text.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(text.substr(i, 2), nullptr, 16)));
  return out;
}

}  // namespace cosmic::peer

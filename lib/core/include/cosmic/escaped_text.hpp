// Text from outside (a configuration value, a URL) as an error message shows it: printable ASCII
// kept, every other byte as \xNN, at most `max_chars` input characters then "...", so a message
// always stays one line whatever it quotes. Pure; any thread.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace cosmic {

inline std::string escaped_text(std::string_view text, std::size_t max_chars) {
  std::string out;
  for (const char c : text.substr(0, max_chars)) {
    if (c >= ' ' && c < 0x7f) {
      out.push_back(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += escaped;
    }
  }
  return text.size() > max_chars ? out + "..." : out;
}

}  // namespace cosmic

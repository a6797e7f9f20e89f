// The candump -l log format (cosmic/candump_log.hpp), after can-utils' lib.c and candump.c.
#include "cosmic/candump_log.hpp"

#include <algorithm>
#include <cstring>

namespace cosmic {
namespace {

constexpr std::size_t kIdOffset = 0;
constexpr std::size_t kLenOffset = 4;
constexpr std::size_t kFlagsOffset = 5;  // canfd_frame's flags; padding (or len8_dlc) in can_frame
constexpr std::size_t kDataOffset = 8;
constexpr std::size_t kClassicMax = 8;
constexpr std::size_t kFdMax = 64;
constexpr std::size_t kMaxInterface = 15;  // IFNAMSIZ less its terminating NUL
constexpr char kDigits[] = "0123456789ABCDEF";

void append_hex(std::uint32_t value, int digits, std::string& out) {
  for (int shift = (digits - 1) * 4; shift >= 0; shift -= 4) out += kDigits[(value >> shift) & 0xF];
}

void append_decimal(std::int64_t value, int min_digits, std::string& out) {
  char text[24];
  int n = 0;
  do {
    text[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value > 0);
  while (n < min_digits) text[n++] = '0';
  while (n > 0) out += text[--n];
}

int nibble(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool is_space(char c) { return c == ' ' || c == '\t'; }

std::optional<std::uint32_t> parse_hex(std::string_view digits) {
  std::uint32_t value = 0;
  for (char c : digits) {
    const int n = nibble(c);
    if (n < 0) return std::nullopt;
    value = (value << 4) | static_cast<std::uint32_t>(n);
  }
  return value;
}

// The identifier bits a log line can say (what sprint_canframe prints): the error frame's flag and
// class bits, else the extended or standard identifier; the remote flag on classic frames only.
std::uint32_t loggable_id(std::uint32_t can_id, bool fd) {
  const std::uint32_t remote = fd ? 0 : can_id & kCandumpRtrFlag;
  if (can_id & kCandumpErrFlag) return (can_id & (kCandumpErrFlag | kCandumpEffMask)) | remote;
  if (can_id & kCandumpEffFlag) return (can_id & (kCandumpEffFlag | kCandumpEffMask)) | remote;
  return (can_id & kCandumpSffMask) | remote;
}

Error bad(std::string what) { return Error{std::move(what)}; }

// The data bytes after the identifier (classic or FD), '.' allowed before each.
Result<void> parse_data(std::string_view text, std::size_t max, CandumpFrame& frame) {
  std::size_t at = 0;
  std::size_t count = 0;
  while (at < text.size()) {
    if (text[at] == '.') ++at;
    if (at + 2 > text.size()) return bad("data ends in half a byte or a '.'");
    const int high = nibble(text[at]);
    const int low = nibble(text[at + 1]);
    if (high < 0 || low < 0) return bad("data byte '" + std::string(text.substr(at, 2)) + "' is not hex");
    if (count == max) return bad("more than " + std::to_string(max) + " data bytes");
    frame.data[count++] = static_cast<std::uint8_t>(high << 4 | low);
    at += 2;
  }
  frame.len = static_cast<std::uint8_t>(count);
  return {};
}

}  // namespace

std::optional<CandumpFrame> candump_frame_from_wire(std::span<const std::uint8_t> bytes) {
  if (bytes.size() != kCanMtu && bytes.size() != kCanFdMtu) return std::nullopt;
  CandumpFrame frame;
  frame.fd = bytes.size() == kCanFdMtu;
  std::memcpy(&frame.can_id, bytes.data() + kIdOffset, sizeof frame.can_id);
  frame.can_id = loggable_id(frame.can_id, frame.fd);
  const bool remote = (frame.can_id & kCandumpRtrFlag) != 0;
  frame.len = std::min(bytes[kLenOffset], static_cast<std::uint8_t>(frame.fd ? kFdMax : kClassicMax));
  frame.flags = frame.fd ? static_cast<std::uint8_t>(bytes[kFlagsOffset] & 0xF) : 0;
  if (!remote) std::copy_n(bytes.begin() + kDataOffset, frame.len, frame.data.begin());
  return frame;
}

std::size_t candump_frame_to_wire(const CandumpFrame& frame, std::span<std::uint8_t, kCanFdMtu> out) {
  std::fill(out.begin(), out.end(), 0);
  std::memcpy(out.data() + kIdOffset, &frame.can_id, sizeof frame.can_id);
  out[kLenOffset] = frame.len;
  if (frame.fd) out[kFlagsOffset] = frame.flags;
  const bool remote = !frame.fd && (frame.can_id & kCandumpRtrFlag);
  if (!remote) std::copy_n(frame.data.begin(), std::min<std::size_t>(frame.len, kFdMax), out.begin() + kDataOffset);
  return frame.fd ? kCanFdMtu : kCanMtu;
}

void append_candump_frame(const CandumpFrame& frame, std::string& out) {
  if (frame.can_id & kCandumpErrFlag) {
    append_hex(frame.can_id & (kCandumpEffMask | kCandumpErrFlag), 8, out);
  } else if (frame.can_id & kCandumpEffFlag) {
    append_hex(frame.can_id & kCandumpEffMask, 8, out);
  } else {
    append_hex(frame.can_id & kCandumpSffMask, 3, out);
  }
  out += '#';
  const std::size_t len = std::min<std::size_t>(frame.len, frame.fd ? kFdMax : kClassicMax);
  if (!frame.fd && (frame.can_id & kCandumpRtrFlag)) {
    out += 'R';
    if (len > 0) out += kDigits[len];
    return;
  }
  if (frame.fd) {
    out += '#';
    out += kDigits[frame.flags & 0xF];
  }
  for (std::size_t i = 0; i < len; ++i) append_hex(frame.data[i], 2, out);
}

void append_candump_line(std::int64_t utc_ns, std::string_view interface, const CandumpFrame& frame, std::string& out) {
  const std::int64_t micros = std::max<std::int64_t>(utc_ns, 0) / 1000;
  out += '(';
  append_decimal(micros / 1'000'000, 10, out);
  out += '.';
  append_decimal(micros % 1'000'000, 6, out);
  out += ") ";
  out += interface;
  out += ' ';
  append_candump_frame(frame, out);
  out += '\n';
}

Result<CandumpFrame> parse_candump_frame(std::string_view text) {
  const std::size_t hash = text.find('#');
  if (hash != 3 && hash != 8) return bad("the identifier is not 3 or 8 hex digits before '#'");
  const auto id = parse_hex(text.substr(0, hash));
  if (!id) return bad("identifier '" + std::string(text.substr(0, hash)) + "' is not hex");
  CandumpFrame frame;
  if (hash == 3) {
    if (*id > kCandumpSffMask) return bad("standard identifier over 7FF");
    frame.can_id = *id;
  } else if (*id & (kCandumpEffFlag | kCandumpRtrFlag)) {
    return bad("extended identifier over 1FFFFFFF");
  } else if (*id & kCandumpErrFlag) {
    frame.can_id = *id;  // 8 digits with the error flag: an error frame (not an extended one)
  } else {
    frame.can_id = *id | kCandumpEffFlag;
  }
  std::string_view rest = text.substr(hash + 1);
  if (!rest.empty() && (rest.front() == 'R' || rest.front() == 'r')) {
    frame.can_id |= kCandumpRtrFlag;
    rest.remove_prefix(1);
    if (rest.empty()) return frame;
    const int dlc = rest.size() == 1 ? nibble(rest.front()) : -1;
    if (dlc < 0 || dlc > static_cast<int>(kClassicMax)) return bad("a remote request's DLC is one digit 0 to 8");
    frame.len = static_cast<std::uint8_t>(dlc);
    return frame;
  }
  std::size_t max = kClassicMax;
  if (!rest.empty() && rest.front() == '#') {
    const int flags = rest.size() >= 2 ? nibble(rest[1]) : -1;
    if (flags < 0) return bad("a CAN FD frame needs its flags nibble after '##'");
    frame.fd = true;
    frame.flags = static_cast<std::uint8_t>(flags);
    max = kFdMax;
    rest.remove_prefix(2);
  }
  if (auto data = parse_data(rest, max, frame); !data) return std::move(data).error();
  return frame;
}

Result<CandumpLine> parse_candump_line(std::string_view line) {
  if (line.ends_with('\n')) line.remove_suffix(1);
  if (line.ends_with('\r')) line.remove_suffix(1);
  if (!line.starts_with('(')) return bad("a log line starts with '(' and the time");
  const std::size_t dot = line.find('.');
  const std::size_t close = line.find(')');
  if (dot == std::string_view::npos || close == std::string_view::npos || dot > close)
    return bad("the time is not (SECONDS.MICROSECONDS)");
  const std::string_view seconds = line.substr(1, dot - 1);
  const std::string_view micros = line.substr(dot + 1, close - dot - 1);
  const auto all_digits = [](std::string_view s) {
    return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (seconds.empty() || seconds.size() > 12 || !all_digits(seconds))
    return bad("the time's seconds are not 1 to 12 decimal digits");
  if (micros.size() != 6 || !all_digits(micros)) return bad("the time's fraction is not 6 decimal digits");
  CandumpLine out;
  for (char c : seconds) out.utc_us = out.utc_us * 10 + (c - '0');
  std::int64_t fraction = 0;
  for (char c : micros) fraction = fraction * 10 + (c - '0');
  out.utc_us = out.utc_us * 1'000'000 + fraction;

  std::string_view rest = line.substr(close + 1);
  const auto skip_space = [&] {
    const std::size_t n = std::min(rest.find_first_not_of(" \t"), rest.size());
    rest.remove_prefix(n);
    return n > 0;
  };
  const auto token = [&] {
    std::size_t n = 0;
    while (n < rest.size() && !is_space(rest[n])) ++n;
    const std::string_view t = rest.substr(0, n);
    rest.remove_prefix(n);
    return t;
  };
  if (!skip_space()) return bad("no space after the time");
  const std::string_view interface = token();
  if (interface.empty() || interface.size() > kMaxInterface) return bad("the interface name is not 1 to 15 characters");
  out.interface = std::string(interface);
  if (!skip_space()) return bad("no frame after the interface");
  const std::string_view frame_text = token();
  if (!rest.empty()) return bad("more than time, interface and frame on the line");
  auto frame = parse_candump_frame(frame_text);
  if (!frame) return bad("frame '" + std::string(frame_text) + "': " + frame.error().text);
  out.frame = frame.value();
  return out;
}

}  // namespace cosmic

#include "metrics_http_head.hpp"

#include <array>

namespace cosmicd {
namespace {

constexpr std::string_view kEnd = "\r\n\r\n";

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

}  // namespace

std::size_t RequestHead::feed(std::string_view bytes) {
  if (state_ != State::incomplete) return 0;
  const std::size_t before = text_.size();
  // The end may straddle two pieces: look again at the last three bytes already held.
  const std::size_t scan_from = before < kEnd.size() - 1 ? 0 : before - (kEnd.size() - 1);
  text_.append(bytes.substr(0, limit_ - before));
  const std::size_t end = text_.find(kEnd, scan_from);
  if (end != std::string::npos) {
    text_.resize(end + kEnd.size());
    state_ = State::complete;
  } else if (text_.size() >= limit_) {
    state_ = State::too_large;
  }
  return text_.size() - before;
}

bool ignored_field(std::string_view line) {
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos) return false;
  std::string_view name = line.substr(0, colon);
  // cpp-httplib takes the name as written; whitespace before the colon is refused by RFC 9112,
  // but a field that might still be read as Range goes too.
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.remove_suffix(1);
  static constexpr std::array<std::string_view, 2> kIgnored = {"range", "if-range"};
  for (const std::string_view ignored : kIgnored) {
    if (equals_ignoring_case(name, ignored)) return true;
  }
  return false;
}

std::string RequestHead::forwarded() const {
  std::string out;
  out.reserve(text_.size());
  std::size_t begin = 0;
  bool request_line = true;
  while (begin < text_.size()) {
    // Lines end at LF, as cpp-httplib splits them.
    std::size_t end = text_.find('\n', begin);
    end = end == std::string::npos ? text_.size() : end + 1;
    const std::string_view line(text_.data() + begin, end - begin);
    if (request_line || !ignored_field(line)) out.append(line);
    request_line = false;
    begin = end;
  }
  return out;
}

}  // namespace cosmicd
